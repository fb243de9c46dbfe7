"""The ROS 2 message types of the bags: ROS 2 Humble's standard ones (``rosbags``' type
store) and MoveIt's ``DisplayTrajectory`` with what it needs, registered from the ``.msg``
text of ``moveit_msgs`` (humble branch, BSD-3-Clause, comments left out) and of
``object_recognition_msgs/ObjectType``. The bag carries these definitions, so any reader
decodes the messages without MoveIt installed."""

from __future__ import annotations

import functools

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

MOVEIT_MSGS = {
    "object_recognition_msgs/msg/ObjectType": "string key\nstring db\n",
    "moveit_msgs/msg/CollisionObject": """std_msgs/Header header
geometry_msgs/Pose pose
string id
object_recognition_msgs/ObjectType type
shape_msgs/SolidPrimitive[] primitives
geometry_msgs/Pose[] primitive_poses
shape_msgs/Mesh[] meshes
geometry_msgs/Pose[] mesh_poses
shape_msgs/Plane[] planes
geometry_msgs/Pose[] plane_poses
string[] subframe_names
geometry_msgs/Pose[] subframe_poses
byte ADD=0
byte REMOVE=1
byte APPEND=2
byte MOVE=3
byte operation
""",
    "moveit_msgs/msg/AttachedCollisionObject": """string link_name
CollisionObject object
string[] touch_links
trajectory_msgs/JointTrajectory detach_posture
float64 weight
""",
    "moveit_msgs/msg/RobotState": """sensor_msgs/JointState joint_state
sensor_msgs/MultiDOFJointState multi_dof_joint_state
AttachedCollisionObject[] attached_collision_objects
bool is_diff
""",
    "moveit_msgs/msg/RobotTrajectory": """trajectory_msgs/JointTrajectory joint_trajectory
trajectory_msgs/MultiDOFJointTrajectory multi_dof_joint_trajectory
""",
    "moveit_msgs/msg/DisplayTrajectory": """string model_id
RobotTrajectory[] trajectory
RobotState trajectory_start
""",
}

JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
DISPLAY_TRAJECTORY = "moveit_msgs/msg/DisplayTrajectory"
JOINT_STATE = "sensor_msgs/msg/JointState"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"


@functools.cache
def typestore() -> Typestore:
    """ROS 2 Humble's types with MoveIt's registered."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in MOVEIT_MSGS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store
