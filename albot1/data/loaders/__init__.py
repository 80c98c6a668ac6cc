"""File-format loaders: one class per format, found through :mod:`.registry`."""

from albot1.data.loaders.base import SequenceLoader, SequenceWriter
from albot1.data.loaders.registry import FORMATS, load, loader_for, writer_for

__all__ = ["FORMATS", "SequenceLoader", "SequenceWriter", "load", "loader_for", "writer_for"]
