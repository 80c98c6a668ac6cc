"""ROS 1 bags and ROS 2 bags (sqlite3, MCAP), read and written through ``rosbags``.

The face of the format is its loaders and writers (``rosbags`` itself is
imported only when one of them reads or writes); message conversions
(``msg``), topic choice (``topics``) and the readers behind the loaders are
the package's own.
"""

from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.writer import Ros1BagWriter, Ros2McapWriter, Ros2Sqlite3Writer

__all__ = ["Ros1BagLoader", "Ros1BagWriter", "Ros2BagLoader", "Ros2McapWriter", "Ros2Sqlite3Writer"]
