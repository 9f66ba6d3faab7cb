"""Motion profiles: piecewise-linear mechanical speed and its exact angle integral.

Profile text: comma-separated items "rpm:seconds" (constant speed; 0 = hold) or
"rpm_start-rpm_end:seconds" (linear ramp); speeds may be negative ("-30:2",
"200--200:0.5" ramps from +200 to -200 r/min). Named presets are listed in PRESETS.
Before t = 0 and after the end the shaft keeps its first/last speed, so filters that
need a past (the R/D loop's settling, delays) see a consistent motion.
"""
import re

import numpy as np

from .conventions import RPM_TO_RAD_S

# Named profiles [rpm:seconds]. Each one is a kind of log users bring (issue 13).
PRESETS = {
    # 1X resolver bench: standstill, one revolution forward at 30 r/min, standstill,
    # one revolution back, standstill (30 r/min for 2 s = 1 revolution).
    "out_and_back": "0:1,30:2,0:1,-30:2,0:1",
    # Speed steps at constant speed each: delay and tracking-loop effects grow with speed.
    "speed_steps": "100:2,300:2,600:2,1000:2",
    # Reversals through linear ramps and one abrupt reversal (speed step through zero).
    "reversals": "120:1.5,120--120:0.5,-120:1.5,-120-120:0.5,120:1.5,60:1,-60:1",
    # A slow turn: one revolution in 30 s.
    "slow_turn": "2:30",
    # Ramp up and down: lag of a type-II loop under constant acceleration.
    "ramps": "0:0.5,0-600:2,600:1,600-0:2,0:0.5",
}

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ITEM = re.compile(rf"^\s*({_NUM})\s*(?:-\s*({_NUM}))?\s*:\s*({_NUM})\s*$")


class ProfileError(ValueError):
    """A profile text that cannot be parsed; the message names the item."""


def parse_profile(text):
    """Parses profile text or a preset name into [(rpm_start, rpm_end, seconds)].

    Raises ProfileError naming the bad item and its position."""
    source = PRESETS.get(text.strip(), text)
    items = []
    for index, item in enumerate(source.split(","), start=1):
        match = _ITEM.match(item)
        if not match:
            raise ProfileError(
                f"profile item {index} '{item.strip()}': expected rpm:seconds or "
                f"rpm_start-rpm_end:seconds (e.g. 30:2, 0-600:2, 200--200:0.5), "
                f"or a preset name ({', '.join(sorted(PRESETS))})")
        rpm0 = float(match.group(1))
        rpm1 = float(match.group(2)) if match.group(2) is not None else rpm0
        seconds = float(match.group(3))
        if not seconds > 0.0:
            raise ProfileError(f"profile item {index} '{item.strip()}': duration must be > 0 s")
        items.append((rpm0, rpm1, seconds))
    return items


class MotionProfile:
    """theta_m(t) [rad] and omega_m(t) [rad/s] for piecewise-linear speed."""

    def __init__(self, items, start_angle=0.0):
        """items: [(rpm_start, rpm_end, seconds)]; start_angle: theta_m(0) [rad]."""
        if not items:
            raise ProfileError("profile is empty")
        self.items = list(items)
        self.duration = np.array([s for _, _, s in items], dtype=float)
        self.w0 = np.array([a for a, _, _ in items], dtype=float) * RPM_TO_RAD_S
        self.w1 = np.array([b for _, b, _ in items], dtype=float) * RPM_TO_RAD_S
        self.t_start = np.concatenate(([0.0], np.cumsum(self.duration)[:-1]))
        self.total = float(np.sum(self.duration))
        # Angle travelled in each segment: trapezoid of a linear speed (exact).
        travel = 0.5 * (self.w0 + self.w1) * self.duration
        self.theta_start = start_angle + np.concatenate(([0.0], np.cumsum(travel)[:-1]))
        self.theta_end = float(start_angle + np.sum(travel))

    def _locate(self, t):
        t = np.asarray(t, dtype=float)
        idx = np.clip(np.searchsorted(self.t_start, t, side="right") - 1, 0, len(self.items) - 1)
        return t, idx, t - self.t_start[idx]

    def theta(self, t):
        """Mechanical angle [rad], unwrapped, exact for linear speed ramps."""
        t, idx, tau = self._locate(t)
        accel = (self.w1[idx] - self.w0[idx]) / self.duration[idx]
        inside = self.theta_start[idx] + self.w0[idx] * tau + 0.5 * accel * tau * tau
        before = self.theta_start[0] + self.w0[0] * t
        after = self.theta_end + self.w1[-1] * (t - self.total)
        return np.where(t < 0.0, before, np.where(t > self.total, after, inside))

    def omega(self, t):
        """Mechanical speed [rad/s]."""
        t, idx, tau = self._locate(t)
        accel = (self.w1[idx] - self.w0[idx]) / self.duration[idx]
        inside = self.w0[idx] + accel * tau
        return np.where(t < 0.0, self.w0[0], np.where(t > self.total, self.w1[-1], inside))

    def accel(self, t):
        """Mechanical acceleration [rad/s^2] (0 outside the profile)."""
        t, idx, _ = self._locate(t)
        a = (self.w1[idx] - self.w0[idx]) / self.duration[idx]
        return np.where((t < 0.0) | (t > self.total), 0.0, a)

    def direction_runs(self):
        """Maximal runs of one direction of motion, holds merged into the run before.

        Returns (boundaries [s], directions): run r spans boundaries[r-1]..boundaries[r]
        (the first starts at -inf, the last ends at +inf) with direction +1 or -1.
        A reversal through a ramp is at the ramp's zero crossing; a reversal across a
        hold is placed at the end of the hold (the angle does not move in between).
        Returns ([], [0]) when the shaft never moves."""
        pieces = []  # (t_begin, sign) of each sub-interval with constant speed sign
        for k in range(len(self.items)):
            t0, d, a, b = self.t_start[k], self.duration[k], self.w0[k], self.w1[k]
            if a * b < 0.0:  # ramp through zero: split at the crossing
                crossing = t0 + d * a / (a - b)
                pieces += [(t0, np.sign(a)), (crossing, np.sign(b))]
            else:
                pieces.append((t0, np.sign(a) if a != 0.0 else np.sign(b)))
        moving = [(t, int(s)) for t, s in pieces if s != 0]
        if not moving:
            return [], [0]
        boundaries, directions = [], [moving[0][1]]
        for t, s in moving[1:]:
            if s != directions[-1]:
                boundaries.append(t)
                directions.append(s)
        return boundaries, directions

    def describe(self):
        """JSON-ready description of the segments."""
        return [{"t_start_s": float(t), "seconds": float(d), "rpm_start": float(a), "rpm_end": float(b)}
                for t, d, (a, b, _) in zip(self.t_start, self.duration, self.items)]
