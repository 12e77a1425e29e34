"""Interactive 3-D views of a plan in the browser (MeshCat): :mod:`flipkit.viz.motion` samples
a plan on one clock, :mod:`flipkit.viz.scene` draws the cell and :mod:`flipkit.viz.viewer`
the animated arm, spatula and burger (``flipkit view``, ``docs/viewer.md``)."""
