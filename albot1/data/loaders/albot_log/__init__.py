"""The albot-log format: the Albot1 robot's own text log (SENSOR and VIEW lines), read and written.

The face of the format is its loader and writer; the line grammar
(``lines``) is the package's own.
"""

from albot1.data.loaders.albot_log.loader import AlbotLogLoader, AlbotLogWriter

__all__ = ["AlbotLogLoader", "AlbotLogWriter"]
