"""Reader for LCM event-log files (what lcm-logger and resolverd's file:// URL write).

Pure Python, standard library only: Debian ships no Python LCM module.

Each event in the file is, big-endian (LCM's "log file format"):

    uint32 sync word 0xEDA1DA01
    int64  event number          (0, 1, 2, ... in the order written)
    int64  timestamp             [us since the Unix epoch] when the logger got the message
    int32  channel length        [bytes]
    int32  data length           [bytes]
    channel                      UTF-8, not NUL-terminated
    data                         the message exactly as published (8-byte fingerprint + body)

Like resolver-echo's C++ reader (tools/echo/lcm_eventlog_reader.h) it does not
skip garbage to the next sync word, as liblcm does: a bad sync word, a
truncated event or an impossible length raises EventLogError naming the file,
the byte offset and the event (#1 = the first), after every good event before
it has been yielded.
"""

import os
import struct
from dataclasses import dataclass
from typing import Iterator, Union

SYNC_WORD = 0xEDA1DA01
_HEADER = struct.Struct(">IqqII")  # sync, event number, timestamp, channel length, data length
HEADER_SIZE = _HEADER.size  # 28 bytes
# LCM refuses channel names longer than this; a longer one means a corrupt header.
MAX_CHANNEL_LENGTH = 255


class EventLogError(Exception):
    """A log file that cannot be read on: names the file, the event and the byte offset."""


@dataclass(frozen=True)
class Event:
    """One logged message."""

    event_number: int  # as the writer numbered it
    timestamp_us: int  # [us] since the Unix epoch, when the logger received it
    channel: str
    data: bytes  # the encoded message: fingerprint (8 bytes) + body
    offset: int  # [bytes] position of the event's sync word in the file
    index: int  # position in the file: 0 = the first event


def read_events(path: Union[str, os.PathLike]) -> Iterator[Event]:
    """Yields the events of the log at `path` in file order.

    Raises OSError if the file cannot be opened, EventLogError when its
    content is not an LCM event log (after yielding the good events before).
    """
    path = os.fspath(path)
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        offset = 0
        index = 0  # events read so far; the number of the one being read
        while True:
            header = f.read(HEADER_SIZE)
            if not header:
                return  # clean end of file
            # Worded as resolver-echo's C++ reader words it (event numbers from 1).
            where = f"{path}: byte offset {offset} (event #{index + 1} in the file)"
            if len(header) < HEADER_SIZE:
                raise EventLogError(
                    f"{where}: truncated header ({len(header)} of {HEADER_SIZE} bytes; "
                    "was the log still being written?)")
            sync, number, timestamp, channel_len, data_len = _HEADER.unpack(header)
            if sync != SYNC_WORD:
                raise EventLogError(
                    f"{where}: bad sync word 0x{sync:08X} (expected 0x{SYNC_WORD:08X}); "
                    "not an LCM event log, or corrupt here")
            # The lengths are int32 in the format; above 2^31 they are negative there.
            if channel_len == 0 or channel_len > MAX_CHANNEL_LENGTH:
                raise EventLogError(f"{where}: channel length {channel_len} outside 1..{MAX_CHANNEL_LENGTH}")
            body_end = offset + HEADER_SIZE + channel_len + data_len
            if data_len >= 2**31 or body_end > size:
                raise EventLogError(
                    f"{where}: truncated event (channel {channel_len} + data {data_len} bytes "
                    f"run past the end of the file at byte {size})")
            raw_channel = f.read(channel_len)
            data = f.read(data_len)
            try:
                channel = raw_channel.decode("utf-8")
            except UnicodeDecodeError as e:
                raise EventLogError(f"{where}: channel name is not UTF-8 ({e.reason})") from None
            yield Event(number, timestamp, channel, data, offset, index)
            offset = body_end
            index += 1


def write_events(path: Union[str, os.PathLike], events) -> None:
    """Writes (channel, data, timestamp_us) tuples as an event log (for tests and tools)."""
    with open(path, "wb") as f:
        for number, (channel, data, timestamp_us) in enumerate(events):
            raw_channel = channel.encode("utf-8")
            f.write(_HEADER.pack(SYNC_WORD, number, timestamp_us, len(raw_channel), len(data)))
            f.write(raw_channel)
            f.write(data)
