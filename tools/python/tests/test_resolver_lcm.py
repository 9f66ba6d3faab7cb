#!/usr/bin/env python3
"""Unit tests of resolver_lcm (PYTHONPATH=build/python): the event-log reader on
synthetic logs, including broken ones, and load_log's columns with and without numpy.

The logs are written with eventlog.write_events from messages encoded by the
generated classes; the integration test (test_lcmlog_example.py) checks the
reader against logs resolverd wrote and against resolver-echo.
"""

import contextlib
import io
import math
import os
import re
import struct
import tempfile
import unittest

from resolver_lcm import EventLogError, LOG_TIME_COLUMN, LogMessage, load_log, read_events
from resolver_lcm.eventlog import HEADER_SIZE, SYNC_WORD, write_events
from resolver_lcm.resolver import angle_t, dq_t, estimate_t

try:
    import numpy
except ImportError:
    numpy = None


def make_angle(i):
    m = angle_t()
    m.utime = 1_700_000_000_000_000 + 500 * i
    m.sample_index = i
    m.counter = i % 256
    m.theta_rd = 0.001 * i
    m.theta_comp = 0.001 * i + 1e-5
    m.theta_ref = math.nan if i == 1 else 0.001 * i  # NaN must survive as NaN
    return m


def make_estimate(i, n_params):
    m = estimate_t()
    m.utime = i
    m.method = "hwang_integral"
    m.num_params = n_params
    m.param_name = [f"effect.p{k}" for k in range(n_params)]
    m.value = [0.003 * (k + 1) for k in range(n_params)]
    m.std_error = [1e-5] * n_params
    m.converged = i > 0
    return m


def make_dq(i):
    m = dq_t()
    m.sample_index = i
    m.ripple_order = [2, 6, 12]
    m.i_d_ripple_raw = [0.1 * i, 0.2, 0.3]
    m.ripple_valid = True
    return m


class TempLog:
    """A log file in a temporary folder, removed afterwards."""

    def __init__(self, events=None, raw=None):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "test.lcmlog")
        if raw is not None:
            with open(self.path, "wb") as f:
                f.write(raw)
        else:
            write_events(self.path, events)

    def __enter__(self):
        return self.path

    def __exit__(self, *exc):
        self.dir.cleanup()


def standard_events():
    events = []
    for i in range(5):
        events.append(("RESOLVER_ANGLE", make_angle(i).encode(), 1000 + 10 * i))
        events.append(("RESOLVER_DQ", make_dq(i).encode(), 1001 + 10 * i))
    # Variable-length arrays of two lengths: must stay per-message lists.
    events.append(("RESOLVER_ESTIMATE", make_estimate(0, 1).encode(), 2000))
    events.append(("RESOLVER_ESTIMATE", make_estimate(1, 3).encode(), 2010))
    return events


class ReadEventsTest(unittest.TestCase):
    def test_round_trip(self):
        events = standard_events()
        with TempLog(events) as path:
            read = list(read_events(path))
        self.assertEqual(len(read), len(events))
        offset = 0
        for n, (event, (channel, data, t)) in enumerate(zip(read, events)):
            self.assertEqual((event.event_number, event.index, event.channel, event.data, event.timestamp_us),
                             (n, n, channel, data, t))
            self.assertEqual(event.offset, offset)
            offset += HEADER_SIZE + len(channel) + len(data)

    def test_empty_file_has_no_events(self):
        with TempLog(raw=b"") as path:
            self.assertEqual(list(read_events(path)), [])
            self.assertEqual(load_log(path).channels, {})

    def test_bad_sync_word_names_event_and_offset_after_the_good_events(self):
        events = standard_events()[:3]
        with TempLog(events) as path:
            with open(path, "rb") as f:
                raw = bytearray(f.read())
        second = HEADER_SIZE + len(events[0][0]) + len(events[0][1])
        third = second + HEADER_SIZE + len(events[1][0]) + len(events[1][1])
        raw[third] ^= 0xFF  # corrupt the third event's sync word
        with TempLog(raw=bytes(raw)) as path:
            got = []
            with self.assertRaises(EventLogError) as ctx:
                for e in read_events(path):
                    got.append(e)
        self.assertEqual(len(got), 2)
        self.assertIn(f"byte offset {third} (event #3 in the file)", str(ctx.exception))
        self.assertIn("bad sync word", str(ctx.exception))

    def test_truncated_event_and_header(self):
        events = standard_events()[:2]
        with TempLog(events) as path:
            with open(path, "rb") as f:
                raw = f.read()
        second = HEADER_SIZE + len(events[0][0]) + len(events[0][1])
        # Cut 3 bytes before the end (inside the last event's data), or 10 bytes into its header.
        for cut, what in ((len(raw) - 3, "truncated event"), (second + 10, "truncated header")):
            with self.subTest(what=what), TempLog(raw=raw[:cut]) as path:
                got = []
                with self.assertRaises(EventLogError) as ctx:
                    for e in read_events(path):
                        got.append(e)
                self.assertEqual(len(got), 1)
                self.assertIn(what, str(ctx.exception))
                self.assertIn(f"byte offset {second} (event #2 in the file)", str(ctx.exception))

    def test_impossible_channel_length(self):
        raw = struct.pack(">IqqII", SYNC_WORD, 0, 0, 300, 0) + b"x" * 300
        with TempLog(raw=raw) as path:
            with self.assertRaisesRegex(EventLogError, "channel length 300"):
                list(read_events(path))

    def test_not_a_log(self):
        with TempLog(raw=b"(1700000000.000000) can0 101#00\n" * 3) as path:
            with self.assertRaisesRegex(EventLogError, r"byte offset 0 \(event #1 in the file\): bad sync word"):
                list(read_events(path))


class LoadLogTest(unittest.TestCase):
    def check_columns(self, log, arrays):
        angle = log["RESOLVER_ANGLE"]
        self.assertEqual((angle.count, angle.type_name), (5, "resolver.angle_t"))
        self.assertEqual(list(angle[LOG_TIME_COLUMN]), [1000, 1010, 1020, 1030, 1040])
        self.assertEqual(list(angle["sample_index"]), [0, 1, 2, 3, 4])
        self.assertEqual(float(angle["theta_comp"][4]), 0.004 + 1e-5)
        self.assertTrue(math.isnan(angle["theta_ref"][1]))
        dq = log["RESOLVER_DQ"]
        estimate = log["RESOLVER_ESTIMATE"]
        self.assertEqual(list(estimate["param_name"][1]), ["effect.p0", "effect.p1", "effect.p2"])
        self.assertEqual(list(estimate["value"][0]), [0.003])
        self.assertIsInstance(estimate["value"], list)  # ragged: one list per message
        self.assertIsInstance(estimate["method"], list)  # strings stay lists
        if arrays:
            self.assertIsInstance(angle["theta_comp"], numpy.ndarray)
            self.assertEqual(angle["theta_comp"].dtype, numpy.float64)
            self.assertEqual(dq["ripple_order"].shape, (5, 3))  # fixed-size array: 2-D
            self.assertEqual(dq["i_d_ripple_raw"][4, 0], 0.1 * 4)
            self.assertEqual(dq["ripple_valid"].dtype, numpy.bool_)
        else:
            self.assertIsInstance(angle["theta_comp"], list)
            self.assertEqual(dq["ripple_order"][3], [2, 6, 12])
            self.assertEqual(dq["i_d_ripple_raw"][4][0], 0.1 * 4)

    def test_columns_as_lists(self):
        with TempLog(standard_events()) as path:
            self.check_columns(load_log(path, use_numpy=False), arrays=False)

    @unittest.skipIf(numpy is None, "python3-numpy not installed")
    def test_columns_as_numpy_arrays(self):
        with TempLog(standard_events()) as path:
            self.check_columns(load_log(path), arrays=True)

    def test_environment_switch_forces_lists(self):
        os.environ["RESOLVER_LCM_NO_NUMPY"] = "1"
        try:
            with TempLog(standard_events()) as path:
                self.check_columns(load_log(path), arrays=False)
        finally:
            del os.environ["RESOLVER_LCM_NO_NUMPY"]

    def test_channel_filter(self):
        with TempLog(standard_events()) as path:
            log = load_log(path, channels=["RESOLVER_DQ"], use_numpy=False)
        self.assertEqual(list(log.channels), ["RESOLVER_DQ"])

    def test_unknown_type_is_counted_not_dropped(self):
        events = standard_events() + [("OTHER", b"\x01" * 8 + b"payload", 3000)] * 2
        with TempLog(events) as path:
            log = load_log(path, use_numpy=False)
        self.assertEqual(log.undecoded, {"OTHER": 2})
        self.assertNotIn("OTHER", log)

    def test_two_types_on_one_channel_is_an_error(self):
        events = standard_events() + [("RESOLVER_ANGLE", make_dq(9).encode(), 3000)]
        with TempLog(events) as path:
            with self.assertRaisesRegex(ValueError, "RESOLVER_ANGLE carries resolver.dq_t after resolver.angle_t"):
                load_log(path)

    def test_short_message_names_the_event(self):
        events = standard_events() + [("RESOLVER_ANGLE", make_angle(9).encode()[:20], 3000)]
        with TempLog(events) as path:
            with self.assertRaisesRegex(ValueError, rf"\(event #{len(events)} in the file\): resolver.angle_t on RESOLVER_ANGLE does not decode"):
                load_log(path)


class IterationTest(unittest.TestCase):
    def test_for_msg_in_log_yields_decoded_messages_in_order(self):
        events = standard_events()
        with TempLog(events + [("OTHER", b"\x01" * 8 + b"payload", 3000)]) as path:
            log = load_log(path, use_numpy=False)
            got = list(log)
            self.assertEqual(len(list(log)), len(events))  # iterates again, from the start
        self.assertEqual([(m.channel, m.log_time_us) for m in got], [(c, t) for c, _, t in events])  # OTHER skipped
        self.assertIsInstance(got[0], LogMessage)
        self.assertIsInstance(got[0].message, angle_t)
        self.assertEqual(got[2].message.theta_comp, 0.001 + 1e-5)
        self.assertEqual(list(got[-1].message.param_name), ["effect.p0", "effect.p1", "effect.p2"])

    def test_channel_filter_applies_to_iteration(self):
        with TempLog(standard_events()) as path:
            log = load_log(path, channels=["RESOLVER_DQ"])
            self.assertEqual([m.message.sample_index for m in log], [0, 1, 2, 3, 4])

    def test_integer_index_says_how_to_iterate(self):
        with TempLog(standard_events()) as path:
            log = load_log(path, use_numpy=False)
        with self.assertRaisesRegex(TypeError, "indexed by channel name.*for msg in log"):
            log[0]


README = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "README.md")


def readme_python_snippet():
    """The first ```python block of the README's "Python: resolverd's logs as arrays"."""
    with open(README, encoding="utf-8") as f:
        text = f.read()
    section = text.split("\n## Python: resolverd's logs as arrays\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"^```python\n(.*?)^```$", section, re.S | re.M).group(1)


class ReadmeSnippetTest(unittest.TestCase):
    """The README's Python example, exactly as printed there, on a generated log."""

    def run_snippet(self):
        snippet = readme_python_snippet()
        self.assertIn('"/tmp/demo.lcmlog"', snippet)
        self.assertNotIn("pandas", snippet)
        with TempLog(standard_events()) as path:
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(compile(snippet.replace('"/tmp/demo.lcmlog"', repr(path)), "README.md", "exec"), {})
        return out.getvalue()

    def test_snippet_runs_with_numpy_if_installed(self):
        self.assertIn("5 dq messages", self.run_snippet())

    def test_snippet_runs_without_numpy(self):
        os.environ["RESOLVER_LCM_NO_NUMPY"] = "1"
        try:
            out = self.run_snippet()
        finally:
            del os.environ["RESOLVER_LCM_NO_NUMPY"]
        self.assertIn("first i_d 0.0 A at 1001 us", out)


if __name__ == "__main__":
    unittest.main(verbosity=2)
