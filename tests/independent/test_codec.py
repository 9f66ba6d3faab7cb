"""The candump/ASC bytes: own CRC and encoder against proto/resolver_bench.dbc and python-can."""
import os
import tempfile
import unittest

import numpy as np

import support
from benchgen import crc8, dbc, layouts, readers, writers
from benchgen.bench import BenchConfig, simulate
from benchgen.effects import EffectSet


class Crc8Test(unittest.TestCase):
    def test_check_value(self):
        # CRC-8 SAE J1850 catalogue check value (reveng "CRC-8/SAE-J1850": check=0x4b).
        self.assertEqual(crc8.crc8(b"123456789"), 0x4B)

    def test_vectorised_equals_scalar(self):
        rows = np.random.default_rng(7).integers(0, 256, (200, 7), dtype=np.uint8)
        for can_id in (0x100, 0x1F0):
            want = [crc8.crc8(bytes(r) + bytes([can_id & 0xFF])) for r in rows]
            self.assertEqual(crc8.frame_crc(rows, can_id).tolist(), want)


class DefaultLayoutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.config = BenchConfig(profile="0:0.3,150:1,-150:0.7", sample_rate=1000.0, p_r=2, p=4,
                                 effects=EffectSet(["amplitude_imbalance:alpha=0.01",
                                                    "noise:sigma_sc=3,sigma_i=0.02",
                                                    "quantization:rd_bits=12"]))
        cls.samples = simulate(cls.config)
        cls.frames = layouts.encode(cls.samples, cls.config)
        cls.log = os.path.join(cls.tmp.name, "bench.log")
        cls.asc = os.path.join(cls.tmp.name, "bench.asc")
        index = np.arange(len(cls.frames))
        writers.write_candump(cls.log, cls.frames, index, cls.frames.t, support.START_US)
        writers.write_asc(cls.asc, cls.frames, index, cls.frames.t, support.START_US)
        cls.stamps, cls.ids, cls.data, cls.dlc = readers.read_candump(cls.log)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_frame_counts_and_crc(self):
        n = len(self.samples)
        for can_id in (0x100, 0x101, 0x102):
            self.assertEqual(np.count_nonzero(self.ids == can_id), n)
        # BENCH_INFO at 10 Hz over 2.0 s: 20 frames.
        self.assertEqual(np.count_nonzero(self.ids == 0x1F0), 20)
        for can_id, fields in readers.decode_default(self.ids, self.data).items():
            self.assertTrue(fields["crc_ok"].all(), f"CRC of 0x{can_id:03X}")
        self.assertTrue((self.dlc == 8).all())
        self.assertTrue((np.diff(self.stamps) >= 0).all(), "a clean log is time ordered")

    def test_counters_join_samples(self):
        fields = readers.decode_default(self.ids, self.data)
        want = np.arange(len(self.samples)) % 256
        for can_id in (0x100, 0x101, 0x102):
            self.assertEqual(fields[can_id]["counter"].tolist(), want.tolist())

    def test_decodes_through_the_bench_dbc(self):
        # Our byte-level encoder read through the project's DBC (an independent path).
        decoded = readers.decode_with_dbc(self.ids, self.data, support.BENCH_DBC)
        s = self.samples
        np.testing.assert_array_equal(decoded["RESOLVER_SAMPLE"]["sin"], s.sin)
        np.testing.assert_array_equal(decoded["RESOLVER_SAMPLE"]["cos"], s.cos)
        # rd_angle: 12-bit code in the top bits; the DBC factor is 2 pi / 65536 per bit.
        np.testing.assert_allclose(decoded["RESOLVER_SAMPLE"]["rd_angle"], s.rd_angle, atol=1e-12)
        lsb16 = 2 * np.pi / 65536
        raw = np.rint(decoded["RESOLVER_SAMPLE"]["rd_angle"] / lsb16).astype(int)
        self.assertTrue((raw % 16 == 0).all(), "low 16 - rd_bits bits are zero")
        for k in ("i_a", "i_b", "i_c"):  # 1 mA/bit: rounding within half a bit
            np.testing.assert_allclose(decoded["PHASE_CURRENTS"][k], getattr(s, k), atol=0.0005 + 1e-9)
        ref = decoded["REFERENCE_ANGLE"]["ref_angle"]
        np.testing.assert_allclose(support.wrap(ref - s.ref_angle), 0.0, atol=support.REF_HALF_LSB * 1.01)
        self.assertTrue((decoded["REFERENCE_ANGLE"]["reserved"] == 0).all())
        info = decoded["BENCH_INFO"]
        self.assertTrue((info["layout_version"] == 1).all())
        self.assertTrue((info["p_r"] == 2).all() and (info["p"] == 4).all())
        self.assertTrue((info["rd_bits"] == 12).all() and (info["sample_rate_hz"] == 1000).all())
        crc_dbc = {name: decoded[name]["crc"] for name in decoded}
        fields = readers.decode_default(self.ids, self.data)
        for name, can_id in (("RESOLVER_SAMPLE", 0x100), ("BENCH_INFO", 0x1F0)):
            np.testing.assert_array_equal(crc_dbc[name], self.data[self.ids == can_id][:, 7])
            self.assertTrue(fields[can_id]["crc_ok"].all())

    def test_python_can_reads_the_candump_log(self):
        import can
        messages = list(can.CanutilsLogReader(self.log))
        self.assertEqual(len(messages), len(self.ids))
        self.assertEqual([m.arbitration_id for m in messages], self.ids.tolist())
        self.assertEqual(b"".join(bytes(m.data) for m in messages), self.data.tobytes())
        np.testing.assert_allclose([m.timestamp for m in messages], self.stamps / 1e6, atol=1e-6)

    def test_python_can_reads_the_asc_log(self):
        import can
        messages = [m for m in can.ASCReader(self.asc) if not m.is_error_frame]
        self.assertEqual(len(messages), len(self.ids))
        self.assertEqual([m.arbitration_id for m in messages], self.ids.tolist())
        self.assertEqual(b"".join(bytes(m.data) for m in messages), self.data.tobytes())
        # ASC times are relative to the first frame.
        np.testing.assert_allclose([m.timestamp for m in messages], (self.stamps - self.stamps[0]) / 1e6,
                                   atol=1e-6)


class DbcCodecTest(unittest.TestCase):
    def test_round_trip_random_signals(self):
        # Randomised round trip of the codec over both byte orders, signs and lengths.
        rng = np.random.default_rng(11)
        for _ in range(300):
            length = int(rng.integers(1, 33))
            little = bool(rng.integers(0, 2))
            signed = bool(rng.integers(0, 2)) and length > 1
            if little:
                start = int(rng.integers(0, 64 - length + 1))
            else:  # Motorola start = MSB; the LSB must stay inside 8 bytes
                msb = int(rng.integers(length - 1, 64))  # position in the big-endian word
                start = (7 - msb // 8) * 8 + msb % 8
            signal = dbc.Signal("x", start, length, little, signed, 1.0, 0.0, 0, 0, "")
            low = -(1 << (length - 1)) if signed else 0
            high = (1 << (length - 1)) - 1 if signed else (1 << length) - 1
            raw = rng.integers(low, high + 1, 16)
            rows = rng.integers(0, 256, (16, 8)).astype(np.uint8)
            before = rows.copy()
            signal.insert(rows, raw)
            np.testing.assert_array_equal(signal.raw(rows), raw)
            # Other bits untouched: clearing the signal's bits in both leaves equal rows.
            signal.insert(rows, np.zeros(16, dtype=np.int64))
            signal.insert(before, np.zeros(16, dtype=np.int64))
            np.testing.assert_array_equal(rows, before)

    def test_motorola_byte_positions(self):
        # A 16-bit big-endian signal with start bit 15 occupies bytes 1 (MSB) and 2 (LSB).
        signal = dbc.Signal("x", 15, 16, False, False, 1.0, 0.0, 0, 0, "")
        rows = np.zeros((1, 8), dtype=np.uint8)
        signal.insert(rows, np.array([0x1234]))
        self.assertEqual(rows[0].tolist(), [0, 0x12, 0x34, 0, 0, 0, 0, 0])


class OtherLayoutsTest(unittest.TestCase):
    def _log(self, layout, **overrides):
        config = BenchConfig(effects=EffectSet(["quadrature:beta=0.01", "noise:sigma_i=0.05"]), **overrides)
        samples = simulate(config)
        frames = layouts.encode(samples, config, layout)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "x.log")
            writers.write_candump(path, frames, np.arange(len(frames)), frames.t, support.START_US)
            stamps, ids, data, _ = readers.read_candump(path)
        decoded = readers.decode_with_dbc(ids, data, layouts.DBC_LAYOUTS[layout].dbc_path)
        return samples, ids, decoded

    def test_angle_only_degrees_no_counter(self):
        samples, ids, decoded = self._log("angle_only", profile="out_and_back", sample_rate=100.0, p_r=1, p=4)
        self.assertEqual(set(ids.tolist()), {0x200})
        self.assertEqual(len(ids), len(samples))  # one message per sample, nothing else (no BENCH_INFO)
        deg = 180.0 / np.pi
        # 0.0001 deg/bit: rounding within half a bit.
        half_bit = 0.00005 + 1e-9
        rd = decoded["ANGLES"]["rd_angle"]
        self.assertTrue(((rd >= 0) & (rd < 360)).all())
        np.testing.assert_allclose(support.wrap((rd - samples.rd_angle * deg) / deg) * deg, 0.0, atol=half_bit)
        ref = decoded["ANGLES"]["ref_angle"]
        np.testing.assert_allclose(support.wrap((ref - samples.ref_angle * deg) / deg) * deg, 0.0, atol=half_bit)

    def test_big_endian_with_counter(self):
        samples, ids, decoded = self._log("be_counter", profile="reversals")
        n = len(samples)
        for name in ("RES_FB", "CUR_FB", "REF_FB"):
            np.testing.assert_array_equal(decoded[name]["counter"], np.arange(n) % 256)
        np.testing.assert_array_equal(decoded["RES_FB"]["sin"], samples.sin)
        np.testing.assert_array_equal(decoded["RES_FB"]["cos"], samples.cos)
        np.testing.assert_allclose(decoded["RES_FB"]["rd_angle"], samples.rd_angle, atol=1e-12)
        np.testing.assert_allclose(decoded["CUR_FB"]["i_a"], samples.i_a, atol=0.005 + 1e-9)  # 10 mA/bit
        rev = decoded["REF_FB"]["ref_angle"]
        np.testing.assert_allclose(support.wrap(2 * np.pi * rev - samples.ref_angle), 0.0,
                                   atol=support.REF_HALF_LSB * 1.01)


if __name__ == "__main__":
    unittest.main()
