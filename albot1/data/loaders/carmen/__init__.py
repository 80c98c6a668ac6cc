"""The CARMEN log format (the Radish / public SLAM benchmark logs), read and written.

The face of the format is its loader, its writer and the loader's options;
the modules behind it (``probe``, ``parse``, ``frames``, ``poses``,
``interp``, ...) are the package's own.
"""

from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.loaders.carmen.options import CarmenOptions
from albot1.data.loaders.carmen.writer import CarmenWriter

__all__ = ["CarmenLoader", "CarmenOptions", "CarmenWriter"]
