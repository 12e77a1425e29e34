"""Model layer: the arm (pinocchio, and its chain as CasADi SX expressions), orientations,
Bezier outputs, the contact cone, the burger's flight and inverse kinematics. Imports only
:mod:`flipkit.config` and below."""
