"""The analog resolver outputs as functions of time (what the R/D converter and the DSP's
ADC are wired to), unit amplitude.

    s_a(t) = S(theta(t)),  c_a(t) = C(theta(t - tau))   tau = channel_delay (analog cos path)
    theta(t) = p_r theta_rs(t) + control angle errors
A dead channel zeroes both outputs over its interval. The common `delay` and the DSP's
`sampling_skew` are not here: they choose at which times this chain is read (bench.py).
"""
import numpy as np

from .mechanics import ResolverShaft
from .windings import Windings


class SensorChain:
    def __init__(self, profile, effects, p_r, p):
        self.profile = profile
        self.p_r = p_r
        self.shaft = ResolverShaft(profile, effects, p)
        self.windings = Windings(effects)
        self.tau = effects.param("channel_delay", "tau")
        self.dead = [(d["start"], d["end"]) for d in effects.all("dead_channel")]
        drift = effects.get("angle_drift")
        self.drift = (drift["rate"], drift["amp"], drift["period"]) if drift else None
        mixed = effects.get("mixed_order")
        self.mixed = (mixed["amp"], mixed["m"], mixed["n"], mixed["phase"]) if mixed else None

    def electrical_angle(self, t):
        """Resolver electrical angle the windings see [rad], unwrapped."""
        seen, theta_b = self.shaft.angle(t)
        theta = self.p_r * seen
        if self.drift:
            rate, amp, period = self.drift
            theta = theta + rate * t + amp * np.sin(2.0 * np.pi * t / period)
        if self.mixed:
            amp, m, n, phase = self.mixed
            theta = theta + amp * np.sin(m * theta_b + n * self.p_r * theta_b + phase)
        return theta

    def _envelopes(self, t):
        theta = self.electrical_angle(t)
        return self.windings.envelopes(theta, t, self.p_r * self.profile.omega(t))

    def analog(self, t):
        """(s_a, c_a) at times t [s]: the resolver's outputs, unit amplitude."""
        t = np.asarray(t, dtype=float)
        s, c = self._envelopes(t)
        if self.tau:
            _, c = self._envelopes(t - self.tau)
        for start, end in self.dead:
            off = (t >= start) & (t < end)
            s = np.where(off, 0.0, s)
            c = np.where(off, 0.0, c)
        return s, c
