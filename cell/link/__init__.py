"""The controller link: framed, acknowledged messages between the cell computer and the robot
controller over a serial line (see ``docs/protocol.md``).

- :mod:`cell.link.frame`: the frame codec (sync, type, sequence, length, payload, CRC-32).
- :mod:`cell.link.messages`: message types, payload layouts, unit conversion at the edge.
- :mod:`cell.link.transport`: opening ``/dev/ttyS0``, ``socket://host:port`` or a pty.
- :mod:`cell.link.client`: the host side: requests with retries, heartbeat, reconnect.
"""
