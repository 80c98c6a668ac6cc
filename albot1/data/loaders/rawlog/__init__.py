"""MRPT rawlog files (write only): the input of MRPT's SLAM applications.

The face of the format is its writer; ``serialize`` (MRPT's binary
serialisation) is the package's own.
"""

from albot1.data.loaders.rawlog.writer import RawlogWriter

__all__ = ["RawlogWriter"]
