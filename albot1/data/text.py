"""Text files as the line readers see them: a leading UTF-8 byte-order mark is not part of the data.

Windows tools (Notepad, Excel's "CSV UTF-8", PowerShell's ``Out-File``)
start a UTF-8 file with the byte-order mark ``EF BB BF`` (U+FEFF). It marks
the encoding and holds no text, so every text reader here drops it where the
file starts, as Python's ``utf-8-sig`` codec, numpy and most tools do: a CARMEN
log, an albot log, a TUM or KITTI trajectory and a relations file read the
same with or without one (the first line keeps its number). A mark anywhere
else is a character of the line and is refused as such by the line's parser.

The one rule has two entries, one per way a reader takes its text:
:func:`without_bom` for byte streams (the CARMEN and albot-log readers and
their sniffing, after decompression) and :data:`TEXT_ENCODING` for files
opened as text (trajectories, relations).
"""

from __future__ import annotations

import codecs
from collections.abc import Iterable, Iterator

#: The UTF-8 encoding of U+FEFF.
UTF8_BOM = codecs.BOM_UTF8
#: The encoding text files are opened with: UTF-8, a leading byte-order mark dropped.
TEXT_ENCODING = "utf-8-sig"


def without_bom(blocks: Iterable[bytes]) -> Iterator[bytes]:
    """``blocks`` (the pieces of a file's bytes, in order) without a byte-order mark at the start.

    The mark may be split across the first pieces (a decompressor hands out
    what it has), so up to three bytes are held back until it is decided.
    """
    head = b""
    pieces = iter(blocks)
    for block in pieces:
        head += block
        if len(head) < len(UTF8_BOM) and UTF8_BOM.startswith(head):
            continue  # maybe the start of a mark: wait for more
        break
    if head.startswith(UTF8_BOM):
        head = head[len(UTF8_BOM) :]
    if head:
        yield head
    yield from pieces
