"""Peer suite: the project's DBC reader against canmatrix, an independent one.

Every file in dbc/ is written by hand in the style of one real tool's export
(CANdb++: CRLF, the full NS_ list, long names in BA_ attributes, a
VECTOR__INDEPENDENT_SIG_MSG; cantools: float/double via SIG_VALTYPE_, a 64-byte
FD message, a Motorola multiplexor; canmatrix: J1939-style extended IDs, value
tables, mux values above 15; and a file whose last SG_ line has no newline).
For each file that canmatrix (Debian's python3-canmatrix) parses, random
payloads of every message, and one payload per multiplexor page plus an unused
page, are decoded by both: the set of signals present (multiplexing) and every
physical value must agree. dbc_decode (tests/dbc_peer/dbc_decode.cpp) is the
project's parser and codec as a line filter.

Without canmatrix the test is skipped, unless RESOLVER_REQUIRE_CANMATRIX=1 says
it must run (tools/install-deps.sh installs it).
"""
import argparse
import glob
import math
import os
import random
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
DBC_DIR = os.path.join(HERE, "dbc")
RANDOM_PAYLOADS = 200
SEED = 25  # issue 25

try:
    import canmatrix.formats  # noqa: E402  (prints "ldf is not supported" on import; harmless)
    CANMATRIX = True
except ImportError:
    CANMATRIX = False

DECODER = None  # set from --dbc-decode


def canmatrix_decode(frame, data):
    """{signal name: physical value as float} of the signals canmatrix says are present."""
    return {name: float(sig.phys_value) for name, sig in frame.decode(bytes(data)).items()}


def mux_page_values(frame):
    """The multiplexor's page values in the file, and one value no page uses."""
    pages = sorted({s.mux_val for s in frame.signals if s.mux_val is not None})
    unused = next(v for v in range(256) if v not in pages)
    return pages + [unused]


def same(a, b):
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)


class DbcPeerTest(unittest.TestCase):
    def test_files_exist(self):
        self.assertGreaterEqual(len(glob.glob(os.path.join(DBC_DIR, "*.dbc"))), 4)

    def test_every_file_decodes_like_canmatrix(self):
        if not CANMATRIX:
            if os.environ.get("RESOLVER_REQUIRE_CANMATRIX") == "1":
                self.fail("python3-canmatrix is missing but RESOLVER_REQUIRE_CANMATRIX=1; run tools/install-deps.sh")
            self.skipTest("python3-canmatrix not installed (tools/install-deps.sh installs it)")
        rng = random.Random(SEED)
        for path in sorted(glob.glob(os.path.join(DBC_DIR, "*.dbc"))):
            with self.subTest(dbc=os.path.basename(path)):
                self.check_file(path, rng)

    def check_file(self, path, rng):
        name = os.path.basename(path)
        try:
            matrix = canmatrix.formats.loadp_flat(path)
        except Exception as e:  # the peer cannot read it: nothing to compare, the project still must
            matrix = None
            print("%s: canmatrix cannot parse it (%r); only checking that dbc_decode reads it" % (name, e))
        cases = []  # (frame, id, extended, payload)
        if matrix is not None:
            for frame in matrix.frames:
                if frame.name == "VECTOR__INDEPENDENT_SIG_MSG":
                    continue  # signals of no frame; the project drops the pseudo message
                size = frame.size
                payloads = [bytearray(rng.getrandbits(8) for _ in range(size)) for _ in range(RANDOM_PAYLOADS)]
                if frame.is_multiplexed:
                    # The multiplexors of these files are byte 0 (Intel 0|8 or Motorola 7|8).
                    for page in mux_page_values(frame):
                        for _ in range(20):
                            data = bytearray(rng.getrandbits(8) for _ in range(size))
                            data[0] = page
                            payloads.append(data)
                for data in payloads:
                    cases.append((frame, frame.arbitration_id.id, frame.arbitration_id.extended, data))
        stdin = "".join("%X %s %s\n" % (i, "x" if ext else "s", bytes(d).hex()) for _, i, ext, d in cases)
        proc = subprocess.run([DECODER, path], input=stdin, capture_output=True, text=True, timeout=120)
        self.assertEqual(proc.returncode, 0, "%s: dbc_decode refused it: %s" % (name, proc.stderr))
        self.assertEqual(proc.stderr, "", "%s: the parser warned: %s" % (name, proc.stderr))
        ours = []
        current = {}
        for line in proc.stdout.splitlines():
            if line == "E":
                ours.append(current)
                current = {}
            elif line == "U":
                current = None
            else:
                _, _message, signal, value = line.split("\t")
                current[signal] = float(value)
        self.assertEqual(len(ours), len(cases), name)
        compared = 0
        for (frame, can_id, _, data), got in zip(cases, ours):
            where = "%s: %s (0x%X) payload %s" % (name, frame.name, can_id, bytes(data).hex())
            self.assertIsNotNone(got, where + ": dbc_decode does not know the ID")
            want = canmatrix_decode(frame, data)
            self.assertEqual(sorted(got), sorted(want), where + ": signals present differ")
            for signal, value in want.items():
                self.assertTrue(same(got[signal], value),
                                "%s: %s = %r, canmatrix says %r" % (where, signal, got[signal], value))
                compared += 1
        print("%s: %d frames, %d values agree with canmatrix" % (name, len(cases), compared))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--dbc-decode", required=True, help="path of the dbc_decode program")
    args, rest = parser.parse_known_args()
    DECODER = args.dbc_decode
    unittest.main(argv=[sys.argv[0], "-v"] + rest)
