"""An LCM event log as columns: one array per field, per channel.

    from resolver_lcm import load_log
    log = load_log("demo.lcmlog")
    angle = log["RESOLVER_ANGLE"]
    angle.count, angle.type_name              # 20000, 'resolver.angle_t'
    angle["theta_comp"]                      # numpy array [rad], or a list without numpy
    angle["log_time_us"]                     # when the logger received each message [us]
    for msg in log:                           # every decoded message, in the file's order
        msg.channel, msg.log_time_us, msg.message.theta_comp

With numpy (Debian: python3-numpy) every numeric field becomes an ndarray:
scalars 1-D, fixed-size arrays (dq_t.ripple_order[3]) 2-D (messages x 3).
Strings and variable-length arrays (estimate_t.param_name[num_params]) stay
Python lists, one entry per message. Without numpy every column is a list.
"""

import os
from dataclasses import dataclass, field
from typing import Dict, Iterator, List, NamedTuple, Optional, Union

from .eventlog import read_events
from .types import find_type, fields, type_name

LOG_TIME_COLUMN = "log_time_us"  # the event's timestamp, not a message field


def _numpy():
    """numpy, or None when it is missing or RESOLVER_LCM_NO_NUMPY=1 (to test the list path)."""
    if os.environ.get("RESOLVER_LCM_NO_NUMPY") == "1":
        return None
    try:
        import numpy
    except ImportError:
        return None
    return numpy


@dataclass
class ChannelData:
    """Every decoded message of one channel, column by column."""

    channel: str
    type_name: str
    count: int = 0
    columns: Dict[str, list] = field(default_factory=dict)

    def __getitem__(self, name):
        return self.columns[name]

    def field_names(self) -> List[str]:
        return list(self.columns)


class LogMessage(NamedTuple):
    """One decoded message of a log, as iterating a LogData yields it."""

    channel: str
    log_time_us: int  # the event's timestamp: when the logger received the message [us]
    message: object   # the lcm-gen class instance (resolver.angle_t, ...)


@dataclass
class LogData:
    """load_log's result: channels by name, plus what could not be decoded.

    log["RESOLVER_ANGLE"] is a channel's columns; `for msg in log` yields every
    decoded message (LogMessage) in the file's order, reading the file again
    (so a long log is never held twice in memory); undecoded messages are skipped
    there as in the columns (counted in `undecoded`).
    """

    channels: Dict[str, ChannelData] = field(default_factory=dict)
    # channel -> number of messages with a fingerprint none of our types has
    undecoded: Dict[str, int] = field(default_factory=dict)
    path: Optional[str] = None
    wanted: Optional[frozenset] = None  # load_log's channel filter (None: every channel)

    def __getitem__(self, channel) -> ChannelData:
        if not isinstance(channel, str):
            raise TypeError(f"a log is indexed by channel name (one of {sorted(self.channels)}), "
                            f"not {type(channel).__name__}; `for msg in log` iterates its messages")
        return self.channels[channel]

    def __iter__(self) -> Iterator[LogMessage]:
        if self.path is None:
            return
        for event, cls, message in _decoded_events(self.path, self.wanted):
            if cls is not None:
                yield LogMessage(event.channel, event.timestamp_us, message)

    def __contains__(self, channel) -> bool:
        return channel in self.channels


def _is_rectangular_numeric(values) -> bool:
    """True when every value is a number, or every value a sequence of numbers of one length."""
    first = values[0]
    if isinstance(first, (bool, int, float)):
        return all(isinstance(v, (bool, int, float)) for v in values)
    if isinstance(first, (list, tuple)):
        n = len(first)
        return all(isinstance(v, (list, tuple)) and len(v) == n and
                   all(isinstance(x, (bool, int, float)) for x in v) for v in values)
    return False


def _to_arrays(columns: Dict[str, list], variable_length: set, np) -> Dict[str, object]:
    if np is None:
        return columns
    out = {}
    for name, values in columns.items():
        # A variable-length array stays ragged even when every message of this
        # log happens to have the same length: its shape must not depend on the data.
        if values and name not in variable_length and _is_rectangular_numeric(values):
            out[name] = np.asarray(values)
        else:
            out[name] = values
    return out


def _variable_length_fields(cls) -> set:
    """Array members whose length is another member (num_params, ...).

    lcm-gen's constructor leaves those empty and fills fixed-size arrays with zeros.
    """
    fresh = cls()
    return {name for name in fields(cls) if getattr(fresh, name) == []}


def _decoded_events(path, wanted):
    """(event, class, message) for each event of the wanted channels; (event, None, None)
    when no type has the event's fingerprint. Raises ValueError for a message that does
    not decode as its type."""
    for event in read_events(path):
        if wanted is not None and event.channel not in wanted:
            continue
        cls = find_type(event.data)
        if cls is None:
            yield event, None, None
            continue
        try:
            message = cls.decode(event.data)
        except Exception as e:  # generated code raises ValueError or struct.error
            raise ValueError(f"{os.fspath(path)}: byte offset {event.offset} (event #{event.index + 1} in the file): "
                             f"{type_name(cls)} on {event.channel} does not decode: {e}") from None
        yield event, cls, message


def load_log(path: Union[str, os.PathLike], channels: Optional[List[str]] = None,
             use_numpy: Optional[bool] = None) -> LogData:
    """Reads the event log at `path` into columns per channel.

    channels: only these (default: every channel). use_numpy: None = if
    installed, False = plain lists. Messages of an unknown type are counted in
    LogData.undecoded, never dropped silently. Raises OSError, EventLogError
    (a corrupt log) or ValueError (a message that does not decode as its type).
    """
    np = _numpy() if use_numpy in (None, True) else None
    if use_numpy and np is None:
        raise ImportError("use_numpy=True but numpy is not importable (Debian: apt-get install python3-numpy)")
    wanted = frozenset(channels) if channels is not None else None
    rows: Dict[str, Dict[str, list]] = {}
    types = {}
    result = LogData(path=os.fspath(path), wanted=wanted)
    for event, cls, message in _decoded_events(path, wanted):
        if cls is None:
            result.undecoded[event.channel] = result.undecoded.get(event.channel, 0) + 1
            continue
        if types.setdefault(event.channel, cls) is not cls:
            raise ValueError(f"{os.fspath(path)}: byte offset {event.offset} (event #{event.index + 1} in the file): channel "
                             f"{event.channel} carries {type_name(cls)} after {type_name(types[event.channel])}")
        columns = rows.get(event.channel)
        if columns is None:
            columns = rows[event.channel] = {name: [] for name in [LOG_TIME_COLUMN] + fields(cls)}
        columns[LOG_TIME_COLUMN].append(event.timestamp_us)
        for name in fields(cls):
            value = getattr(message, name)
            columns[name].append(list(value) if isinstance(value, tuple) else value)
    for channel, columns in rows.items():
        cls = types[channel]
        result.channels[channel] = ChannelData(channel, type_name(cls), len(columns[LOG_TIME_COLUMN]),
                                               _to_arrays(columns, _variable_length_fields(cls), np))
    return result
