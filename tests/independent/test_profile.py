"""Motion profiles: parsing, the exact angle integral, directions of motion."""
import unittest

import numpy as np

from benchgen.profile import PRESETS, MotionProfile, ProfileError, parse_profile

RPM = 2 * np.pi / 60


class ParseTest(unittest.TestCase):
    def test_items(self):
        self.assertEqual(parse_profile("0:1,30:2,-30:2"), [(0, 0, 1), (30, 30, 2), (-30, -30, 2)])
        self.assertEqual(parse_profile("200--200:0.5"), [(200, -200, 0.5)])
        self.assertEqual(parse_profile("-200-200:0.5"), [(-200, 200, 0.5)])
        self.assertEqual(parse_profile(" 1e2 - 3e2 : 1.5 "), [(100, 300, 1.5)])

    def test_presets_parse(self):
        for name in PRESETS:
            self.assertTrue(parse_profile(name))

    def test_errors_name_the_item(self):
        for text, fragment in (("30:2,abc", "item 2 'abc'"), ("30:0", "duration must be > 0"),
                               ("30", "item 1 '30'")):
            with self.assertRaises(ProfileError) as caught:
                parse_profile(text)
            self.assertIn(fragment, str(caught.exception))


class IntegralTest(unittest.TestCase):
    def test_out_and_back_returns_home(self):
        profile = MotionProfile(parse_profile("out_and_back"), start_angle=0.3)
        # 1 s hold, 30 r/min for 2 s = 1 rev, hold, -1 rev, hold: ends where it started.
        self.assertAlmostEqual(float(profile.theta(profile.total)), 0.3, places=12)
        self.assertAlmostEqual(float(profile.theta(3.0)), 0.3 + 2 * np.pi, places=12)
        self.assertAlmostEqual(float(profile.theta(0.5)), 0.3, places=12)

    def test_ramp_is_exact(self):
        # 0 -> 600 r/min in 2 s: theta = 1/2 a t^2 with a = 600 RPM / 2 s.
        profile = MotionProfile(parse_profile("0-600:2,600:1"))
        accel = 600 * RPM / 2.0
        for t in (0.1, 0.77, 2.0):
            self.assertAlmostEqual(float(profile.theta(t)), 0.5 * accel * t * t, places=10)
        self.assertAlmostEqual(float(profile.theta(2.5)), 0.5 * accel * 4 + 600 * RPM * 0.5, places=10)
        self.assertAlmostEqual(float(profile.omega(1.0)), 300 * RPM, places=12)
        self.assertAlmostEqual(float(profile.accel(1.0)), accel, places=12)

    def test_numerical_integral_of_speed(self):
        # The angle is the integral of the speed: trapezoid on a fine grid converges to it.
        profile = MotionProfile(parse_profile("reversals"))
        t = np.linspace(0, profile.total, 400001)
        omega = profile.omega(t)
        numeric = np.concatenate(([0.0], np.cumsum(0.5 * (omega[1:] + omega[:-1]) * np.diff(t))))
        # Trapezoid error on a speed with steps: <= |jump| dt per step in speed, dt = 2e-5 s.
        self.assertLess(np.max(np.abs(numeric - profile.theta(t))), 300 * RPM * 2e-5)

    def test_extrapolates_at_end_speeds(self):
        profile = MotionProfile(parse_profile("100:1,-50:1"))
        self.assertAlmostEqual(float(profile.theta(-0.5)), -50 * RPM, places=12)
        self.assertAlmostEqual(float(profile.omega(5.0)), -50 * RPM, places=12)


class DirectionTest(unittest.TestCase):
    def test_reversals(self):
        boundaries, directions = MotionProfile(parse_profile("120:1,120--120:0.5,-120:1,0:1,60:1")).direction_runs()
        self.assertEqual(directions, [1, -1, 1])
        self.assertAlmostEqual(boundaries[0], 1.25)  # zero crossing of the ramp
        self.assertAlmostEqual(boundaries[1], 3.5)  # end of the hold before the forward segment

    def test_standstill_only(self):
        self.assertEqual(MotionProfile(parse_profile("0:2")).direction_runs(), ([], [0]))


if __name__ == "__main__":
    unittest.main()
