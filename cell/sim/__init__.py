"""The simulated cell: a controller that speaks the link protocol over a pty or a socket, the
hidden truth it moves (thermal drift, true hole geometry) and a simulated stereo head.

- :mod:`cell.sim.controller`: the controller's protocol and motion logic (no I/O).
- :mod:`cell.sim.world`: the truth: sim clock, drifted kinematics, true holes.
- :mod:`cell.sim.faults`: what to inject (dropped, corrupted, delayed frames, disconnect, e-stop).
- :mod:`cell.sim.server`: the controller served over a pseudo-terminal or a local socket.
- :mod:`cell.sim.camera`: the simulated stereo head behind :class:`cell.camera.CameraBackend`.
"""
