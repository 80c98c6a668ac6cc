"""Data layer: the data model, file-format loaders, the dataset catalog,
synthetic worlds and odometry degradation."""

from albot1.data.model import Frame, Relations, Scan, Sequence, SequenceMetadata
from albot1.data.open import open_sequence

__all__ = ["Frame", "Relations", "Scan", "Sequence", "SequenceMetadata", "open_sequence"]
