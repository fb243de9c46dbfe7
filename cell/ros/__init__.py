"""ROS 2 bags (MCAP storage, written with ``rosbags``) of a tour and of a run, for RViz and
Foxglove (docs/ros.md): ``msgs.py`` (the message types, MoveIt's registered from their
``.msg`` text), ``samples.py`` (the trajectory as messages), ``tour_bag.py``, ``run_bag.py``."""
