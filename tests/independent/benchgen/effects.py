"""The effect catalog as this generator implements it: names, parameters, units, ranges.

Names and parameter names are the project's interface (resolver-sim --list-effects,
issues 13 and 14); keep them exactly. A spec is "name:param=value,param=value" or,
positionally, "name:value,value" in the order listed here. Effects marked catalog=False
are controls outside the catalog: a tool must never give them a catalog name.
Small-parameter signatures (eps = theta_true - theta_measured, resolver electrical rad)
are in each effect's `signature`; tests/independent/test_signatures.py checks them.
"""
from dataclasses import dataclass, field


class EffectError(ValueError):
    """A bad effect spec; the message names the spec, the parameter and what is allowed."""


@dataclass(frozen=True)
class Param:
    name: str
    unit: str
    default: object  # None = required
    low: float = float("-inf")
    high: float = float("inf")
    help: str = ""
    choices: tuple = ()  # non-empty: a word parameter, one of these


@dataclass(frozen=True)
class EffectDef:
    name: str
    group: str  # resolver | current | noise | impairment | frame | control
    params: tuple
    signature: str
    catalog: bool = True
    repeatable: bool = False


def _harmonic_params():
    params = [Param("k0", "1", 0.0, -0.5, 0.5, "inductive DC component K_0 on both windings")]
    params += [Param(f"k{n}", "1", 0.0, -0.5, 0.5, f"K_{n}: s += K sin({n} theta), c += K cos({n} theta)")
               for n in range(2, 21)]
    params += [Param(f"k{n}_opp", "1", 0.0, -0.5, 0.5, f"s += K sin({n} theta), c -= K cos({n} theta)")
               for n in range(2, 21)]
    # Measured harmonics have their own phase: K sin(n theta + phase), K cos(n theta + phase).
    params += [Param(f"k{n}_phase", "rad", 0.0, -7.0, 7.0, f"phase of K_{n} (both windings)")
               for n in range(2, 21)]
    params += [Param(f"k{n}_opp_phase", "rad", 0.0, -7.0, 7.0, f"phase of K_{n}_opp (both windings)")
               for n in range(2, 21)]
    return tuple(params)


def _mechanical_params():
    params = []
    for n in range(1, 17):
        params += [Param(f"a{n}", "rad", 0.0, -0.5, 0.5, f"sin({n} theta_m) term of the angle the resolver sees"),
                   Param(f"b{n}", "rad", 0.0, -0.5, 0.5, f"cos({n} theta_m) term")]
    return tuple(params)


_CHANNELS = ("sin", "cos", "rd", "ref", "i_a", "i_b", "i_c")

CATALOG = {e.name: e for e in (
    # ---- resolver side -------------------------------------------------------------------
    EffectDef("amplitude_imbalance", "resolver",
              (Param("alpha", "1", None, -0.5, 0.5, "cos channel gain error: c x (1 + alpha)"),),
              "eps ~ (alpha/2) sin 2theta (Hanselman eq. 4-5)"),
    EffectDef("quadrature", "resolver",
              (Param("beta", "rad", None, -0.5, 0.5, "cos channel cos(theta + beta)"),),
              "eps ~ -(beta/2)(1 - cos 2theta) (Hanselman eq. 6-7, sign for eps = theta - phi)"),
    EffectDef("offsets", "resolver",
              (Param("o_s", "1", 0.0, -0.5, 0.5, "sin offset, fraction of amplitude"),
               Param("o_c", "1", 0.0, -0.5, 0.5, "cos offset, fraction of amplitude")),
              "eps ~ o_c sin theta - o_s cos theta"),
    EffectDef("harmonics", "resolver", _harmonic_params(),
              "eps ~ -sqrt2 K_0 cos(theta + pi/4) - K_n sin((n-1) theta) (Hanselman eq. 8-9); "
              "opposite sign: eps ~ -K sin((n+1) theta)"),
    EffectDef("envelope_drift", "resolver",
              (Param("g", "1/s", None, -0.01, 0.01,
                     "excitation amplitude drifting: both windings x (1 + g t), t from the first sample"),),
              "eps = 0 (atan2 ignores a common gain); envelope radius x (1 + g t)"),
    EffectDef("eccentricity", "resolver",
              (Param("e", "rad", None, -0.5, 0.5, "1x mechanical angle error amplitude [mech rad]"),
               Param("phase", "rad", 0.0, -10.0, 10.0, "its phase [mech rad]")),
              "eps = -p_r e sin(theta_m + phase)"),
    EffectDef("mechanical_harmonics", "resolver", _mechanical_params(),
              "eps = -p_r sum_n (a_n sin(n theta_m) + b_n cos(n theta_m))"),
    EffectDef("mounting_offset", "resolver",
              (Param("theta_0", "rad", None, -3.15, 3.15, "resolver zero ahead of the rotor d axis [motor electrical rad]"),),
              "eps = -(p_r/p) theta_0; reference-frame i_d = -i_q sin theta_0"),
    EffectDef("backlash", "resolver",
              (Param("h", "rad", None, 0.0, 0.5, "total play between reference and resolver [mech rad]"),),
              "eps = p_r (h/2) sign(omega); the resolver holds during take-up after a reversal"),
    EffectDef("delay", "resolver",
              (Param("d", "s", None, 0.0, 1.0, "every resolver signal (sin/cos, R/D angle) is the one of t - d"),),
              "eps = omega d + every other error evaluated at theta - omega d"),
    EffectDef("channel_delay", "resolver",
              (Param("tau", "s", None, -1e-3, 1e-3, "analog cos path delayed against sin, before the R/D converter"),),
              "quadrature with beta = -omega tau in the R/D angle and the sampled sin/cos"),
    EffectDef("sampling_skew", "resolver",
              (Param("tau", "s", None, -1e-3, 1e-3, "the DSP samples cos tau after sin; the R/D does not see it"),),
              "sampled sin/cos only: quadrature with beta = omega tau"),
    EffectDef("tracking_loop", "resolver",
              (Param("omega_n", "rad/s", None, 0.0, 1e6, "closed-loop natural frequency; 0 = ideal converter"),
               Param("zeta", "1", 0.7, 0.01, 10.0, "damping ratio")),
              "errors filtered by H(s) = (2 zeta omega_n s + omega_n^2)/(s^2 + 2 zeta omega_n s + omega_n^2); "
              "lag a/omega_n^2 under acceleration a"),
    EffectDef("quantization", "resolver",
              (Param("rd_bits", "bits", None, 1, 16, "R/D resolution"),),
              "eps uniform in +-pi/2^rd_bits"),
    # ---- current side --------------------------------------------------------------------
    EffectDef("current_offsets", "current",
              (Param("off_a", "A", 0.0, -1000.0, 1000.0, "offset of sensor a"),
               Param("off_b", "A", 0.0, -1000.0, 1000.0, "offset of sensor b")),
              "dq ripple at 1x theta_e of amplitude hypot(off_a, off_b/sqrt3)"),
    EffectDef("current_gain_mismatch", "current",
              (Param("gain_a", "1", 0.0, -0.5, 0.5, "sensor a x (1 + gain_a)"),
               Param("gain_b", "1", 0.0, -0.5, 0.5, "sensor b x (1 + gain_b)")),
              "dq ripple at 2x theta_e"),
    EffectDef("dead_time", "current",
              (Param("t_d", "s", None, 0.0, 2e-5, "dead time; k = t_d / 100 us"),),
              "each phase + k|I|(sin 7psi - sin 5psi): 6x theta_e ripple 2k|I| perpendicular to the current"),
    # ---- noise ---------------------------------------------------------------------------
    EffectDef("noise", "noise",
              (Param("sigma_sc", "counts", 0.0, 0.0, 32767.0, "white noise on each sin/cos ADC sample"),
               Param("sigma_i", "A", 0.0, 0.0, 1000.0, "white noise on each phase current sample")),
              "sets the floor"),
    # ---- sample-level impairments (repeatable) -------------------------------------------
    EffectDef("outliers", "impairment",
              (Param("rate", "1/s", None, 0.0, 1e5, "mean number of spikes per second (Poisson)"),
               Param("size", "counts|rad|A", None, -1e6, 1e6, "spike size, random sign"),
               Param("channel", "", "sin", choices=_CHANNELS, help="where the spikes land")),
              "impulsive samples: EMI spikes, bit errors", catalog=False, repeatable=True),
    EffectDef("clipping", "impairment",
              (Param("level", "counts", None, 0.0, 32767.0, "DSP ADC saturates sin/cos at +-level"),),
              "flat tops on the sampled envelopes (the R/D front end is not clipped)", catalog=False),
    EffectDef("dead_channel", "impairment",
              (Param("start", "s", None, 0.0), Param("end", "s", None, 0.0)),
              "sin = cos = 0 at the resolver output over [start, end): the R/D sees it too",
              catalog=False, repeatable=True),
    EffectDef("stuck", "impairment",
              (Param("channel", "", "sin", choices=_CHANNELS), Param("start", "s", None, 0.0),
               Param("end", "s", None, 0.0)),
              "the channel keeps its sample of `start` until `end`", catalog=False, repeatable=True),
    # ---- frame-level impairments ---------------------------------------------------------
    EffectDef("dropped_frames", "frame",
              (Param("rate", "1", None, 0.0, 1.0, "probability that a frame (CSV: a row) is lost"),),
              "gaps in the counter and in time", catalog=False),
    EffectDef("duplicated_frames", "frame",
              (Param("rate", "1", None, 0.0, 1.0, "probability that a frame (CSV: a row) is sent twice"),),
              "repeated counters", catalog=False),
    EffectDef("timestamp_jitter", "frame",
              (Param("sigma", "s", None, 0.0, 1.0, "white Gaussian jitter of each timestamp"),),
              "timestamps wander; small sigma keeps them monotonic only by chance", catalog=False),
    EffectDef("timestamp_step", "frame",
              (Param("at", "s", None, 0.0), Param("by", "s", None, -1e6, 1e6, "negative = steps back")),
              "every timestamp from `at` on is shifted by `by`", catalog=False, repeatable=True),
    # ---- controls outside the catalog -----------------------------------------------------
    EffectDef("alpha_drift", "control",
              (Param("rate", "1/s", None, -1.0, 1.0, "alpha(t) = alpha + rate t (a winding warming up)"),),
              "2theta error whose amplitude changes over time", catalog=False),
    EffectDef("angle_drift", "control",
              (Param("rate", "rad/s", 0.0, -1.0, 1.0, "the measured angle gains rate t [electrical rad]"),
               Param("amp", "rad", 0.0, -1.0, 1.0, "plus a slow wander amp sin(2 pi t / period)"),
               Param("period", "s", 60.0, 1e-3, 1e6)),
              "eps = -(rate t + amp sin(2 pi t / period)): changes over time, not with angle", catalog=False),
    EffectDef("mixed_order", "control",
              (Param("amp", "rad", None, -1.0, 1.0, "error amplitude [electrical rad]"),
               Param("m", "1", 5, -64, 64, "order in theta_m"), Param("n", "1", 3, -64, 64, "order in theta"),
               Param("phase", "rad", 0.0, -10.0, 10.0)),
              "eps = -amp sin(m theta_m + n theta + phase): pick m + n p_r outside 1..16 and not a multiple "
              "of p_r for an order no catalog effect has", catalog=False),
    EffectDef("speed_gain", "control",
              (Param("k", "s/rad", None, -1.0, 1.0, "cos channel x (1 + k |omega|), omega resolver electrical [rad/s]"),),
              "2theta error growing with speed (a frequency-dependent filter mismatch)", catalog=False),
    EffectDef("temperature_step", "control",
              (Param("at", "s", None, 0.0), Param("gain", "1", 0.0, -0.5, 0.5, "both windings x (1 + gain) from `at` on"),
               Param("alpha", "1", 0.0, -0.5, 0.5, "cos channel also x (1 + alpha) from `at` on")),
              "a step in time of amplitude and imbalance", catalog=False, repeatable=True),
)}


@dataclass
class Effect:
    name: str
    params: dict = field(default_factory=dict)
    spec: str = ""


def _parse_value(param, text, spec):
    if param.choices:
        if text not in param.choices:
            raise EffectError(f"effect '{spec}': {param.name}='{text}' is not one of {', '.join(param.choices)}")
        return text
    try:
        value = float(text)
    except ValueError:
        raise EffectError(f"effect '{spec}': {param.name}='{text}' is not a number") from None
    if not param.low <= value <= param.high:
        raise EffectError(f"effect '{spec}': {param.name}={value:g} [{param.unit}] is outside "
                          f"[{param.low:g}, {param.high:g}]")
    return value


def parse_effect(spec):
    """Parses one spec into an Effect with every parameter filled (defaults included)."""
    name, _, rest = spec.strip().partition(":")
    definition = CATALOG.get(name)
    if definition is None:
        raise EffectError(f"effect '{spec}': unknown effect '{name}'; known: {', '.join(CATALOG)}")
    by_name = {p.name: p for p in definition.params}
    given = {}
    for position, item in enumerate(filter(None, (s.strip() for s in rest.split(",")))):
        if "=" in item:
            key, _, text = item.partition("=")
            key, text = key.strip(), text.strip()
            if key not in by_name:
                raise EffectError(f"effect '{spec}': unknown parameter '{key}' of {name}; "
                                  f"known: {', '.join(by_name)}")
        else:
            if position >= len(definition.params):
                raise EffectError(f"effect '{spec}': {name} takes at most {len(definition.params)} values")
            key, text = definition.params[position].name, item
        if key in given:
            raise EffectError(f"effect '{spec}': parameter '{key}' given twice")
        given[key] = _parse_value(by_name[key], text, spec)
    params = {}
    for p in definition.params:
        if p.name in given:
            params[p.name] = given[p.name]
        elif p.default is None:
            raise EffectError(f"effect '{spec}': parameter '{p.name}' [{p.unit}] of {name} is required")
        else:
            params[p.name] = p.default
    for a, b in (("start", "end"),):
        if a in params and b in params and not params[a] < params[b]:
            raise EffectError(f"effect '{spec}': {a} must be before {b}")
    return Effect(name, params, spec.strip())


class EffectSet:
    """The effects of one run: at most one of each non-repeatable effect."""

    def __init__(self, specs=()):
        self.effects = []
        for spec in specs:
            effect = parse_effect(spec)
            if not CATALOG[effect.name].repeatable and self.get(effect.name) is not None:
                raise EffectError(f"effect '{spec}': {effect.name} given twice (it is not repeatable)")
            self.effects.append(effect)

    def get(self, name):
        """The parameters of the named effect, or None when it is absent."""
        for effect in self.effects:
            if effect.name == name:
                return effect.params
        return None

    def all(self, name):
        """Every instance of a repeatable effect."""
        return [e.params for e in self.effects if e.name == name]

    def param(self, name, key, default=0.0):
        params = self.get(name)
        return default if params is None else params[key]

    def describe(self):
        """JSON-ready: every effect with every parameter, its group and catalog membership."""
        return [{"name": e.name, "spec": e.spec, "group": CATALOG[e.name].group,
                 "catalog": CATALOG[e.name].catalog, "params": dict(e.params),
                 "units": {p.name: p.unit for p in CATALOG[e.name].params},
                 "signature": CATALOG[e.name].signature} for e in self.effects]


def catalog_text():
    """The --list-effects text."""
    lines = ["Effects (spec: name:param=value,... or name:value,... in this order):", ""]
    for d in CATALOG.values():
        tag = "" if d.catalog else "  [not a catalog effect]"
        tag += "  [repeatable]" if d.repeatable else ""
        lines.append(f"  {d.name:<22} ({d.group}){tag}")
        lines.append(f"      {d.signature}")
        shown = d.params if len(d.params) <= 6 else d.params[:3]
        for p in shown:
            req = "required" if p.default is None else f"default {p.default}"
            rng = f"one of {'|'.join(p.choices)}" if p.choices else f"in [{p.low:g}, {p.high:g}]"
            lines.append(f"      {p.name:<9} [{p.unit}] {p.help} ({req}, {rng})")
        if len(d.params) > 6:
            lines.append(f"      ... {', '.join(p.name for p in d.params[3:])}")
        lines.append("")
    return "\n".join(lines)
