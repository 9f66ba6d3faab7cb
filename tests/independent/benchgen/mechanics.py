"""The angle the resolver rotor sees, from the true (reference) mechanical angle.

    theta_m --backlash play--> theta_b --+ theta_0/p + e sin(theta_b + phase)
                                          + sum_n a_n sin(n theta_b) + b_n cos(n theta_b)--> theta_rs

Backlash is a play (deadband) of total width h [mech rad] between the reference side and
the resolver side: the resolver side moves only while the gap is taken up, so in steady
motion it lags by h/2 in the direction of motion and, after a reversal, it holds still
until the reference has travelled h back. It is evaluated exactly: the play operator's
state changes only at reversals of the profile, which the profile knows in closed form.
Before the first motion the gap is taken up in the direction of that first motion.
"""
import numpy as np


def backlash_play(profile, t, h):
    """Resolver-side mechanical angle [rad] behind a play of total width h [rad]."""
    x = profile.theta(t)
    if h == 0.0:
        return x
    boundaries, directions = profile.direction_runs()
    if directions == [0]:
        return x
    half = 0.5 * h

    def follow(direction, start, angle):
        # One run of one direction: the resolver side is pushed by the near edge of the gap.
        if direction > 0:
            return np.maximum(start, angle - half)
        return np.minimum(start, angle + half)

    starts = [-np.inf if directions[0] > 0 else np.inf]
    for r, boundary in enumerate(boundaries, start=1):
        x_b = float(profile.theta(boundary))
        starts.append(float(follow(directions[r - 1], starts[r - 1], x_b)))
    run = np.searchsorted(np.asarray(boundaries, dtype=float), t, side="right")
    starts = np.asarray(starts)[run]
    dirs = np.asarray(directions)[run]
    return np.where(dirs > 0, np.maximum(starts, x - half), np.minimum(starts, x + half))


class ResolverShaft:
    """Mechanical angle seen by the resolver [rad] as a function of time."""

    def __init__(self, profile, effects, p):
        self.profile = profile
        self.h = effects.param("backlash", "h")
        self.mount = effects.param("mounting_offset", "theta_0") / p  # motor electrical -> mech rad
        ecc = effects.get("eccentricity")
        self.ecc = (ecc["e"], ecc["phase"]) if ecc else None
        mh = effects.get("mechanical_harmonics") or {}
        self.mech = [(n, mh.get(f"a{n}", 0.0), mh.get(f"b{n}", 0.0)) for n in range(1, 17)
                     if mh.get(f"a{n}", 0.0) or mh.get(f"b{n}", 0.0)]

    def coupling_side(self, t):
        """Angle of the resolver's own shaft after the play [mech rad]."""
        return backlash_play(self.profile, t, self.h)

    def angle(self, t):
        """Angle the resolver sees [mech rad]: shaft + mounting offset + geometric errors."""
        theta_b = self.coupling_side(t)
        seen = theta_b + self.mount
        if self.ecc:
            e, phase = self.ecc
            seen = seen + e * np.sin(theta_b + phase)
        for n, a, b in self.mech:
            seen = seen + a * np.sin(n * theta_b) + b * np.cos(n * theta_b)
        return seen, theta_b
