"""One bench run: the samples an inverter's DSP would stream at t_k = k / fs.

Timing of each resolver signal (docs/ARCHITECTURE.md §7):
  R/D angle     converter driven by the analog chain, read at t_k - d          (delay d)
  DSP sin       analog s at t_k - d
  DSP cos       analog c at t_k - d + tau_s   (sampling_skew tau_s; the R/D does not see it)
  reference     true theta_m(t_k), never delayed
  currents      at t_k, never delayed
Noise and impairments act on the sampled values; the ADC rounds sin/cos to counts and
saturates at +-32767 (full scale, docs/ARCHITECTURE.md §4).
"""
from dataclasses import dataclass, field

import numpy as np

from . import converter
from .chain import SensorChain
from .conventions import TWO_PI
from .currents import machine_currents, sensed_currents
from .effects import EffectSet
from .profile import MotionProfile, parse_profile

FULL_SCALE_COUNTS = 32767  # i16 envelopes (docs/ARCHITECTURE.md §4)

# Fixed ids of the random streams: [seed, stream(, instance)] seeds each one, so adding an
# impairment never changes the draws of another.
STREAM_NOISE_SC, STREAM_NOISE_I, STREAM_OUTLIERS, STREAM_FRAMES = 1, 2, 3, 4


@dataclass
class BenchConfig:
    profile: str = "200:5"  # profile text or preset name (profile.PRESETS)
    sample_rate: float = 2000.0  # [Hz]
    p_r: int = 3  # resolver pole pairs
    p: int = 3  # motor pole pairs
    amplitude: float = 26000.0  # envelope amplitude [counts]
    i_d: float = 0.0  # commanded d current [A]
    i_q: float = 10.0  # commanded q current [A]
    seed: int = 1
    effects: EffectSet = field(default_factory=EffectSet)
    drive_angle: str = "reference"  # "reference" | "rd" (currents.py)
    ref_zero: float = 0.0  # [rad mech] the reference encoder reads theta_m - ref_zero
    start_angle: float = 0.0  # theta_m(0) [rad]
    rd_bits: int = 16  # R/D resolution when no quantization effect is given
    two_sensors: bool = False  # i_c = -(i_a + i_b) from the measured a, b

    def resolution_bits(self):
        bits = self.effects.param("quantization", "rd_bits", self.rd_bits)
        return int(bits)


@dataclass
class Samples:
    t: np.ndarray  # [s] from the start of the log
    theta_m: np.ndarray  # true mechanical angle [rad], unwrapped
    omega_m: np.ndarray  # true mechanical speed [rad/s]
    theta_b: np.ndarray  # resolver-side shaft angle after the backlash play [rad]
    phi: np.ndarray  # converter angle before quantization [rad] (read at t - d)
    rd_code: np.ndarray  # R/D output code in [0, 2^rd_bits)
    rd_bits: int
    sin: np.ndarray  # DSP envelope samples [counts], int
    cos: np.ndarray
    ref_angle: np.ndarray  # reference angle as sent [rad mech], wrapped to [0, 2 pi)
    i_a: np.ndarray  # phase currents as sent [A] (the layout rounds to its resolution)
    i_b: np.ndarray
    i_c: np.ndarray
    substeps: int = 0  # RK4 steps per sample (0 = ideal converter)
    events: list = field(default_factory=list)  # outliers, stuck intervals: for the truth file

    @property
    def rd_angle(self):
        """R/D angle as sent [rad], in [0, 2 pi)."""
        return self.rd_code * (TWO_PI / (1 << self.rd_bits))

    def __len__(self):
        return len(self.t)


def _rng(seed, *stream):
    return np.random.default_rng([int(seed), *stream])


def _add_outliers(config, samples, channels):
    """Poisson spikes of +-size on one channel per outliers effect; recorded as events."""
    duration = len(samples) / config.sample_rate
    for instance, spec in enumerate(config.effects.all("outliers")):
        rng = _rng(config.seed, STREAM_OUTLIERS, instance)
        count = rng.poisson(spec["rate"] * duration)
        index = np.sort(rng.choice(len(samples), size=min(count, len(samples)), replace=False))
        signs = rng.choice([-1.0, 1.0], size=len(index))
        channels[spec["channel"]][index] += signs * spec["size"]
        samples.events += [{"kind": "outlier", "channel": spec["channel"], "index": int(k),
                            "t_s": float(samples.t[k]), "added": float(v)}
                           for k, v in zip(index, signs * spec["size"])]


def _apply_stuck(config, samples, channels):
    for spec in config.effects.all("stuck"):
        inside = np.flatnonzero((samples.t >= spec["start"]) & (samples.t < spec["end"]))
        if len(inside):
            values = channels[spec["channel"]]
            values[inside] = values[inside[0]]
            samples.events.append({"kind": "stuck", "channel": spec["channel"],
                                   "first_index": int(inside[0]), "last_index": int(inside[-1])})


def simulate(config):
    """Runs the bench; returns Samples."""
    fx = config.effects
    profile = MotionProfile(parse_profile(config.profile), config.start_angle)
    period = 1.0 / config.sample_rate
    count = int(round(profile.total * config.sample_rate))
    t = np.arange(count) * period
    chain = SensorChain(profile, fx, config.p_r, config.p)
    delay = fx.param("delay", "d")
    skew = fx.param("sampling_skew", "tau")

    # R/D converter, read at t - d.
    loop = fx.get("tracking_loop")
    substeps = 0
    if loop and loop["omega_n"] > 0.0:
        phi, substeps = converter.tracking_loop(
            chain.analog, -delay, period, count, loop["omega_n"], loop["zeta"],
            lambda when: config.p_r * float(profile.omega(when)))
    else:
        phi = converter.ideal(chain.analog, t - delay)

    # DSP samples of the envelopes (unit amplitude), then counts.
    s_unit, c_unit = chain.analog(t - delay)
    if skew:
        _, c_unit = chain.analog(t - delay + skew)
    sin = config.amplitude * s_unit
    cos = config.amplitude * c_unit
    noise = fx.get("noise") or {"sigma_sc": 0.0, "sigma_i": 0.0}
    if noise["sigma_sc"]:
        rng = _rng(config.seed, STREAM_NOISE_SC)
        sin = sin + rng.normal(0.0, noise["sigma_sc"], count)
        cos = cos + rng.normal(0.0, noise["sigma_sc"], count)

    # Currents at t (not delayed).
    theta_m = profile.theta(t)
    if config.drive_angle == "rd":
        theta_drive = (config.p / config.p_r) * np.unwrap(phi)
    else:
        theta_drive = config.p * theta_m + fx.param("mounting_offset", "theta_0")
    machine = machine_currents(theta_drive, config.i_d, config.i_q, fx.param("dead_time", "t_d"))
    i_a, i_b, i_c = sensed_currents(*machine, fx, config.two_sensors)
    if noise["sigma_i"]:
        rng = _rng(config.seed, STREAM_NOISE_I)
        i_a = i_a + rng.normal(0.0, noise["sigma_i"], count)
        i_b = i_b + rng.normal(0.0, noise["sigma_i"], count)
        i_c = i_c + rng.normal(0.0, noise["sigma_i"], count)
    if config.two_sensors:
        i_c = -(i_a + i_b)

    samples = Samples(t=t, theta_m=theta_m, omega_m=profile.omega(t), theta_b=chain.shaft.coupling_side(t),
                      phi=phi, rd_code=None, rd_bits=config.resolution_bits(), sin=None, cos=None,
                      ref_angle=None, i_a=None, i_b=None, i_c=None, substeps=substeps)
    channels = {"sin": sin, "cos": cos, "rd": np.array(phi, dtype=float), "ref": np.array(theta_m),
                "i_a": np.array(i_a, dtype=float), "i_b": np.array(i_b, dtype=float),
                "i_c": np.array(i_c, dtype=float)}
    _add_outliers(config, samples, channels)
    clip = fx.get("clipping")
    level = min(FULL_SCALE_COUNTS, clip["level"]) if clip else FULL_SCALE_COUNTS
    for name in ("sin", "cos"):
        channels[name] = np.clip(np.rint(channels[name]), -level, level).astype(np.int64)
    channels["rd"] = converter.quantize(channels["rd"], samples.rd_bits)
    _apply_stuck(config, samples, channels)
    samples.sin, samples.cos = channels["sin"], channels["cos"]
    samples.rd_code = channels["rd"]
    samples.ref_angle = np.mod(channels["ref"] - config.ref_zero, TWO_PI)
    samples.i_a, samples.i_b, samples.i_c = channels["i_a"], channels["i_b"], channels["i_c"]
    return samples
