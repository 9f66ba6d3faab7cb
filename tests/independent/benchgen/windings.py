"""Resolver windings: unit-amplitude demodulated envelopes S(theta), C(theta).

Hanselman eq. 8 (inductance harmonics, in phase on both windings) and eq. 16 (amplitude
imbalance multiplies the whole cos winding), eq. 6 (quadrature: cos(theta + beta)), eq. 1's common amplitude V_1 drifting in time
(envelope_drift: both windings x (1 + g t), the excitation warming up), plus:
  - harmonics of opposite sign (an odd nonlinearity of both inputs):
        s += K sin(n theta), c -= K cos(n theta)
  - additive offsets o_s, o_c after the gains (the amplifier/ADC path).
Controls outside the catalog: alpha drifting in time, a cos gain growing with |speed|,
temperature steps of both gains and of alpha.
"""
import numpy as np


class Windings:
    def __init__(self, effects):
        self.alpha = effects.param("amplitude_imbalance", "alpha")
        self.alpha_rate = effects.param("alpha_drift", "rate")
        self.excitation_rate = effects.param("envelope_drift", "g")
        self.beta = effects.param("quadrature", "beta")
        self.o_s = effects.param("offsets", "o_s")
        self.o_c = effects.param("offsets", "o_c")
        harm = effects.get("harmonics") or {}
        self.k0 = harm.get("k0", 0.0)
        self.same = [(n, harm[f"k{n}"], harm.get(f"k{n}_phase", 0.0))
                     for n in range(2, 21) if harm.get(f"k{n}", 0.0)]
        self.opposite = [(n, harm[f"k{n}_opp"], harm.get(f"k{n}_opp_phase", 0.0))
                         for n in range(2, 21) if harm.get(f"k{n}_opp", 0.0)]
        self.speed_k = effects.param("speed_gain", "k")
        self.steps = effects.all("temperature_step")

    def envelopes(self, theta, t, omega):
        """(s, c) at resolver electrical angle theta [rad], time t [s], speed omega [rad/s]."""
        s = np.sin(theta) + self.k0
        c = np.cos(theta + self.beta) + self.k0
        for n, k, ph in self.same:
            s = s + k * np.sin(n * theta + ph)
            c = c + k * np.cos(n * theta + ph)
        for n, k, ph in self.opposite:
            s = s + k * np.sin(n * theta + ph)
            c = c - k * np.cos(n * theta + ph)
        cos_gain = 1.0 + self.alpha + self.alpha_rate * t
        if self.speed_k:
            cos_gain = cos_gain * (1.0 + self.speed_k * np.abs(omega))
        both_gain = 1.0 + self.excitation_rate * np.asarray(t)
        for step in self.steps:
            after = np.asarray(t) >= step["at"]
            both_gain = both_gain * np.where(after, 1.0 + step["gain"], 1.0)
            cos_gain = cos_gain * np.where(after, 1.0 + step["alpha"], 1.0)
        return both_gain * s + self.o_s, both_gain * cos_gain * c + self.o_c
