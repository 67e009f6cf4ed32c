# Copyright 2026 The hyst_id authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Reading what a killed writer left: the complete records of a footer-less MCAP file.

A rosbag2 MCAP file gets its summary and footer only on close. After a crash
(SIGKILL, power cut) the file ends mid-chunk; the MCAP and rosbags readers
refuse it. This module scans the record stream from the start and returns
the schemas, channels and messages of every *complete* record, decompressing
and checking each complete chunk, the way ``mcap recover`` does. It knows
MCAP only; :mod:`hyst_id.io.bag` turns the result into messages.
"""

from __future__ import annotations

from collections.abc import Iterator
import os
from pathlib import Path
import zlib

__all__ = ['MAGIC', 'lacks_footer', 'scan_records']

#: The 8 bytes that open and close every MCAP file.
MAGIC = b'\x89MCAP0\r\n'


def lacks_footer(path: Path) -> bool:
    """Return True for an MCAP file that starts with the magic but has no footer."""
    try:
        with path.open('rb') as fh:
            head = fh.read(8)
            fh.seek(0, os.SEEK_END)
            if fh.tell() < 16:
                return head == MAGIC[:len(head)]
            fh.seek(-8, os.SEEK_END)
            return head == MAGIC and fh.read(8) != MAGIC
    except OSError:
        return False


def _records(buf: bytes, start: int) -> Iterator[tuple[int, memoryview]]:
    """Yield ``(opcode, body)`` of the complete MCAP records in ``buf[start:]``."""
    view = memoryview(buf)
    pos = start
    while pos + 9 <= len(buf):
        length = int.from_bytes(view[pos + 1:pos + 9], 'little')
        if pos + 9 + length > len(buf):
            return
        yield buf[pos], view[pos + 9:pos + 9 + length]
        pos += 9 + length


def _string(body: memoryview, pos: int) -> tuple[str, int]:
    n = int.from_bytes(body[pos:pos + 4], 'little')
    return bytes(body[pos + 4:pos + 4 + n]).decode(), pos + 4 + n


def _decompress(data: bytes, compression: str) -> bytes:
    if compression == '':
        return data
    if compression == 'zstd':
        try:
            from compression import zstd
        except ImportError:
            from backports import zstd
        return zstd.decompress(data)
    if compression == 'lz4':
        from lz4.frame import decompress
        return decompress(data)
    raise ValueError(f'unsupported chunk compression {compression!r}')


def scan_records(raw: bytes) -> tuple[dict, dict, list]:
    """Schemas, channels and messages of the complete records of an MCAP byte string.

    Returns
    -------
    schemas : dict
        ``id -> (name, encoding, text)``.
    channels : dict
        ``id -> (topic, schema id, message encoding)``.
    messages : list
        ``(log_time_ns, channel id, data)`` in file order.

    Raises
    ------
    ValueError
        A complete chunk whose size or CRC does not match (corrupt file).
    """
    schemas: dict[int, tuple[str, str, str]] = {}
    channels: dict[int, tuple[str, int, str]] = {}
    messages: list[tuple[int, int, bytes]] = []

    def scan(buf: bytes, start: int, top: bool) -> None:
        for op, body in _records(buf, start):
            if op == 0x03:
                sid = int.from_bytes(body[:2], 'little')
                name, pos = _string(body, 2)
                enc, pos = _string(body, pos)
                n = int.from_bytes(body[pos:pos + 4], 'little')
                schemas[sid] = (name, enc, bytes(body[pos + 4:pos + 4 + n]).decode())
            elif op == 0x04:
                cid = int.from_bytes(body[:2], 'little')
                sid = int.from_bytes(body[2:4], 'little')
                topic, pos = _string(body, 4)
                enc, _ = _string(body, pos)
                channels[cid] = (topic, sid, enc)
            elif op == 0x05:
                cid = int.from_bytes(body[:2], 'little')
                messages.append((int.from_bytes(body[6:14], 'little'), cid, bytes(body[22:])))
            elif op == 0x06 and top:
                size = int.from_bytes(body[16:24], 'little')
                crc = int.from_bytes(body[24:28], 'little')
                comp, pos = _string(body, 28)
                n = int.from_bytes(body[pos:pos + 8], 'little')
                data = _decompress(bytes(body[pos + 8:pos + 8 + n]), comp)
                if len(data) != size or (crc and zlib.crc32(data) != crc):
                    raise ValueError('chunk checksum or size mismatch: the file is corrupt')
                scan(data, 0, False)
            elif op == 0x02:
                return

    scan(raw, 8, True)
    return schemas, channels, messages
