"""The MeshCat server behind a view: started on localhost, asked for the page, stopped.

MeshCat draws through a server process (tornado and ZeroMQ on 127.0.0.1, ports from 7000
and 6000 up) that keeps the scene and serves the viewer's page. :func:`open_visualizer`
starts one for a :class:`meshcat.Visualizer`, :func:`page` asks it for the scene as one
self-contained HTML file (three.js and every drawing command inlined: it opens offline) and
:func:`close_visualizer` stops it. A server that does not answer within :data:`TIMEOUT_MS`
is an error, not a hang.
"""

from __future__ import annotations

import contextlib
import io

import meshcat
import zmq

from flipkit.errors import FlipkitError

TIMEOUT_MS = 60_000  # ms a reply of the MeshCat server may take


class ViewerError(FlipkitError):
    """The MeshCat server cannot be started or does not answer."""


def open_visualizer() -> meshcat.Visualizer:
    """A :class:`meshcat.Visualizer` with its own server (its page: ``vis.url()``).

    Raises:
        ViewerError: The server cannot be started.
    """
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL
            vis = meshcat.Visualizer()
    except (RuntimeError, OSError, zmq.ZMQError) as exc:
        raise ViewerError(f"the MeshCat server cannot be started: {exc}") from None
    vis.window.zmq_socket.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
    return vis


def page(vis: meshcat.Visualizer) -> str:
    """The scene of ``vis`` as one self-contained HTML page.

    Raises:
        ViewerError: The server did not answer within :data:`TIMEOUT_MS`.
    """
    try:
        return vis.static_html()
    except zmq.ZMQError as exc:
        raise ViewerError(f"the MeshCat server did not answer: {exc}") from None


def wait(vis: meshcat.Visualizer) -> None:
    """Block until the server of ``vis`` stops or the user presses Ctrl-C."""
    proc = getattr(vis.window, "server_proc", None)
    with contextlib.suppress(KeyboardInterrupt):
        if proc is not None:
            proc.wait()


def close_visualizer(vis: meshcat.Visualizer) -> None:
    """Stop the server that :func:`open_visualizer` started (none: nothing to do)."""
    proc = getattr(vis.window, "server_proc", None)
    if proc is not None and proc.poll() is None:
        proc.kill()
        proc.wait()
