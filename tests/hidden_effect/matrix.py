"""The hidden-effect matrix (issues 13 and 14): which effect, at what size, on which profiles,
and where the physics makes two effects indistinguishable.

Sizes: every hidden effect is at least 10x the position noise floor (~2.6e-5 rad: 16-bit R/D
rounding 2 pi / 2^16 / sqrt 12 = 2.8e-5 rad and sin/cos noise 2 counts / 26000 = 7.7e-5 of the
amplitude), so it is named with a wide margin, while the cross terms of the winding effects
with the 0.3 % amplitude imbalance every log carries (second order, alpha x size <= 0.003 x
0.002 = 6e-6 rad) stay far below the floor, so the refit can reach it. The motion effects
are large on purpose (mounting offset 0.05 rad, delay 0.5 ms = up to 0.09 rad at 600 r/min,
backlash 6e-3 rad), as on real benches: they turn the frame in which the resolver's own
errors appear by that much, and a model must carry that.
"""
from dataclasses import dataclass, field

from profiles import PROFILES

ALPHA = "amplitude_imbalance:alpha=0.003"
NOISE = "noise:sigma_sc=2,sigma_i=0.02"  # resolver-sim's default noise, given to both generators
MOVING_WINDING = ("const", "oab3", "oab1", "steps", "reversals", "angle1")


@dataclass(frozen=True)
class Hidden:
    key: str            # test name
    spec: str           # the generators' -e spec
    refs: tuple         # the references the tool may print for it (explicit, then default form)
    params: frozenset   # the parameters the first candidate must fit
    profiles: tuple
    # profile -> (twin references, why the log cannot tell them apart). The first
    # candidate must be the hidden effect or a twin, with all the others in its
    # fits_as_well. A twin "amplitude_imbalance" (in the default model) means absorbed:
    # the default model already explains the log, with alpha moved by `absorbs` x size.
    twins: dict = field(default_factory=dict)
    absorbs: float = 0.0  # d alpha / d size when absorbed by amplitude imbalance
    size: float = 0.0     # the hidden parameter's value (for `absorbs`)
    # profile -> references the log DOES tell apart: they must not be in fits_as_well.
    apart: dict = field(default_factory=dict)
    # profile -> (reference, parameters, why): part of the effect is the default model's
    # already, so the tool names the rest.
    part: dict = field(default_factory=dict)
    # parameter -> (true value, tolerance beyond 5 standard errors, why): the refit with the
    # hidden effect added must find it there.
    truth: dict = field(default_factory=dict)
    # Control: on the logs without it (control_alpha_only, every profile) its candidate's BIC
    # drop stays at or below the proposal threshold (it would not be proposed even if the
    # log were not already explained), or it is not evaluated there.
    quiet_in_control: bool = False


def _h(key, spec, refs, params, profiles, twins=None, **kw):
    return Hidden(key, spec, tuple(refs), frozenset(params), tuple(profiles), twins or {}, **kw)


# Why effects are twins (derivations; the test asserts exactly that the first candidate is
# one of them and lists the others in fits_as_well):
DELAY_BACKLASH = (
    "delay gives eps = omega d, backlash p_r (h/2) sign(omega): with one |omega| in both "
    "directions both are +-c, so only the backlash take-up after the reversal "
    "(h / |omega_m| = 0.004 / 12.6 s = 0.3 ms, under 1 sample) could tell them apart")
CONST_OFFSET = (
    "at one speed in one direction delay (omega d), backlash (p_r h/2) and mounting offset "
    "(-(p_r/p) theta_0; its steady i_d is absorbed by the fit's operating point) are the same "
    "constant eps, each shifting the frame of the winding errors by that constant")
ONE_DIRECTION = (
    "without a reversal backlash is the constant p_r h/2, as a mounting offset (whose steady "
    "i_d the fit's operating point absorbs)")
CHANNEL_QUAD = (
    "channel_delay is quadrature with beta = -omega tau on both the R/D angle and sin/cos; at "
    "one speed that is a fixed beta, exactly quadrature")
K2_OFFSETS = (
    "K_2 puts -K_2 sin theta on the angle (Hanselman eq. 9, (n-1) theta) and offsets o_c sin "
    "theta - o_s cos theta: the same 1 theta term; only the sin/cos envelopes (K_2 at 2 theta, "
    "offsets at DC) tell them apart, and the angle-only map has none")
K3_ALPHA = (
    "K_3 puts -K_3 sin 2theta on the angle (Hanselman eq. 9), amplitude imbalance (alpha/2) "
    "sin 2theta (eq. 5): without sin/cos the model's alpha absorbs it, alpha -> alpha - 2 K_3")
K3_MECH = (
    "in complex form c + j s = e^(j theta) (1 + K_3 e^(j 2theta)): K_3 moves the angle by "
    "-K_3 sin 2theta and the envelope radius by K_3 cos 2theta. With alpha in the model, "
    "alpha + 2 K_3 gives that radius ((alpha/2)(1 + cos 2theta), its constant part absorbed by "
    "the unknown amplitude) and a mechanical order on 2 theta (2 p_r theta_m, an angle error "
    "only) the rest of the angle: even with sin/cos the two models are the same to first order")
K5_K3OPP = (
    "K_5 lands on (5-1) theta, K_3_opp on (3+1) theta, both -K sin 4theta (Hanselman eq. 9 and "
    "its odd-nonlinearity sibling); at p_r = 1 mechanical order 4 too; only sin/cos (K at 5 "
    "theta vs 3 theta on the envelopes) tell them apart")
ECC_OFFSETS_P1 = (
    "with p_r = 1 eccentricity's 1x mechanical error is at 1 theta, like offsets in the angle, and so is "
    "K_2 with its phase (K_2 sin(2 theta + phi) lands on 1 theta: Hanselman eq. 9); without sin/cos nothing "
    "tells them apart")
B2_K3Q_P1 = (
    "at p_r = 1 the cos part b2 of the 2nd mechanical order puts -b2 cos 2theta on the angle, and K_3's "
    "quadrature part k3_q puts -k3_q cos 2theta there too (harmonics.h); only the radius of sin/cos tells them "
    "apart, and this log has none")

HIDDEN = {h.key: h for h in [
    _h("quadrature", "quadrature:beta=0.002", ["quadrature"], ["quadrature.beta"], MOVING_WINDING),
    _h("offsets", "offsets:o_s=0.001,o_c=-0.0015", ["offsets"], ["offsets.o_s", "offsets.o_c"], MOVING_WINDING,
       {"angle1": (("eccentricity", "harmonics(k2,k2_q)"), ECC_OFFSETS_P1)}),
    _h("k3", "harmonics:k3=0.001", ["harmonics(k3)", "harmonics"], ["harmonics.k3"], MOVING_WINDING,
       {"angle1": (("amplitude_imbalance",), K3_ALPHA),
        **{p: (("mechanical_harmonics(a6,b6)",), K3_MECH) for p in ("const", "oab3", "steps", "reversals")},
        "oab1": (("mechanical_harmonics",), K3_MECH)},
       absorbs=-2.0, size=0.001),
    _h("k5", "harmonics:k5=0.0005", ["harmonics(k5)"], ["harmonics.k5"], MOVING_WINDING,
       {"angle1": (("harmonics(k3_opp)",), K5_K3OPP)}),
    _h("k3_opp", "harmonics:k3_opp=0.0005", ["harmonics(k3_opp)"], ["harmonics.k3_opp"], MOVING_WINDING,
       {"angle1": (("harmonics(k5)",), K5_K3OPP)}),
    _h("mechanical_harmonics", "mechanical_harmonics:a2=2e-4,b2=-1e-4",
       ["mechanical_harmonics(a2,b2)", "mechanical_harmonics"],
       ["mechanical_harmonics.a2", "mechanical_harmonics.b2"], MOVING_WINDING,
       {"angle1": (("harmonics(k3_q)",), B2_K3Q_P1)},
       part={"angle1": ("mechanical_harmonics(b2)", ["mechanical_harmonics.b2"],
                        "at p_r = 1 the order 2 of theta_m is 2 theta: its sin part a2 puts -a2 sin 2theta on "
                        "the angle, which the model's alpha takes ((alpha/2) sin 2theta, alpha -> alpha - 2 a2), "
                        "and without sin/cos nothing tells them apart; the cos part b2 is left to name")}),
    _h("eccentricity", "eccentricity:e=5e-4,phase=1", ["eccentricity"],
       ["eccentricity.e", "eccentricity.phase"], MOVING_WINDING,
       {"angle1": (("offsets", "harmonics(k2,k2_q)"), ECC_OFFSETS_P1)}),
    _h("mounting_offset", "mounting_offset:theta_0=0.05", ["mounting_offset"], ["mounting_offset.theta_0"],
       MOVING_WINDING,
       {"const": (("delay", "backlash"), CONST_OFFSET), "steps": (("backlash",), ONE_DIRECTION)}),
    _h("delay", "delay:d=5e-4", ["delay"], ["delay.d"],
       ("const", "oab3", "oab1", "steps", "ramps", "reversals", "angle1"),
       {"const": (("backlash", "mounting_offset"), CONST_OFFSET), "oab3": (("backlash",), DELAY_BACKLASH),
        "oab1": (("backlash",), DELAY_BACKLASH), "angle1": (("backlash",), DELAY_BACKLASH)}),
    _h("backlash", "backlash:h=0.004", ["backlash"], ["backlash.h"],
       ("const", "oab3", "oab1", "steps", "reversals", "angle1"),
       {"const": (("delay", "mounting_offset"), CONST_OFFSET), "steps": (("mounting_offset",), ONE_DIRECTION),
        "oab3": (("delay",), DELAY_BACKLASH), "oab1": (("delay",), DELAY_BACKLASH),
        "angle1": (("delay",), DELAY_BACKLASH)}),
    _h("channel_delay", "channel_delay:tau=2e-5", ["channel_delay"], ["channel_delay.tau"],
       ("const", "oab3", "steps", "ramps", "reversals"),
       {"const": (("quadrature",), CHANNEL_QUAD)}),
    _h("sampling_skew", "sampling_skew:tau=2e-5", ["sampling_skew"], ["sampling_skew.tau"],
       ("const", "steps", "ramps")),
    # The loop's ripple error 1 - H(j w) ~ (w / omega_n)^2 of the 2 theta imbalance ripple
    # (1.5e-3 rad): at 2000 r/min (w = 2 x 628 rad/s) and omega_n = 3000 that is 0.18, 2.6e-4
    # rad (10x the floor); on the 600 r/min ramps only a 1000 rad/s loop is seen
    # ((377/1000)^2 = 0.14, 2e-4 rad), a 3000 rad/s one would be at the floor (2.4e-5).
    _h("tracking_loop", "tracking_loop:omega_n=3000,zeta=0.7", ["tracking_loop"], ["tracking_loop.omega_n"],
       ("loop_ramp",)),
    _h("tracking_loop_1k", "tracking_loop:omega_n=1000,zeta=0.7", ["tracking_loop"], ["tracking_loop.omega_n"],
       ("ramps",)),
    _h("current_gain_mismatch", "current_gain_mismatch:gain_a=0.01,gain_b=-0.005", ["current_gain_mismatch"],
       ["current_gain_mismatch.gain_a", "current_gain_mismatch.gain_b"], ("const", "oab3", "steps")),
    _h("dead_time", "dead_time:t_d=1e-6", ["dead_time"], ["dead_time.t_d"], ("const", "oab3", "steps")),
    # The excitation warming up: both envelopes x (1 + g t). Only the sin/cos radius shows
    # it (no angle moves), so no profile of an angle-only log (angle1); 1e-3 /s (a fast
    # warm-up) moves the radius by 3e-3 over a 3 s log, g T / sqrt 12 = 8.7e-4 rms about
    # its mean (the mean is the unknown amplitude), 11x the sin/cos floor (2 counts /
    # 26000 = 7.7e-5); the cross term with the 0.3 % imbalance (g t alpha / 2 <= 4.5e-6) is
    # far below it. No twin: no other catalog effect changes the radius in time.
    # The fit's radius is r + g t (envelope_drift.h), the chain's (1 + g t)(1 + r) - 1: the
    # mean of r (alpha/2 = 1.5e-3 for the imbalance) multiplies the slope, so the refit
    # finds g (1 + alpha/2), 1.5e-6 above g.
    _h("envelope_drift", "envelope_drift:g=1e-3", ["envelope_drift"], ["envelope_drift.g"],
       ("const", "oab3", "oab1", "steps", "ramps", "reversals"),
       truth={"envelope_drift.g": (1e-3, 1e-3 * 0.003 / 2,
                                   "the radius' cross term g t alpha/2, first order in the fit")},
       quiet_in_control=True),
    # K2 with sin/cos: the envelopes tell it from offsets (named alone); without them
    # (angle1) both fit.
    _h("k2", "harmonics:k2=0.001", ["harmonics(k2)"], ["harmonics.k2"], ("const", "oab1", "angle1"),
       {"angle1": (("offsets", "eccentricity"), K2_OFFSETS + "; at p_r = 1 eccentricity is at 1 theta too")},
       apart={"const": ("offsets",), "oab1": ("offsets",)}),
]}

for _h_ in HIDDEN.values():
    for _p in _h_.profiles:
        assert _p in PROFILES, (_h_.key, _p)

# Controls: ({generator: generator arguments}, profiles, why a generator is missing).
CONTROLS = {
    # Nothing hidden beyond the modelled imbalance: on every profile "explained", nothing
    # proposed (a candidate here would be a false discovery).
    "control_alpha_only": ({"sim": [], "benchgen": []},
                           ("const", "oab3", "oab1", "steps", "ramps", "reversals", "angle1"), ""),
    # Spikes of 3000 counts (0.115 of the amplitude) at 2/s on the sin channel, sampled at
    # f_s = 2 kHz, add sqrt(2 / 2000) x 0.115 = 3.6e-3 rms to sin/cos, 45x its floor: they
    # matter, so the log must never be "explained".
    "control_outliers": ({"sim": ["-e", "outliers:rate=2,size=3000"],
                          "benchgen": ["-e", "outliers:rate=2,size=3000,channel=sin"]}, ("const", "oab3"), ""),
    # Spikes of 0.01 rad on the R/D angle: sqrt(2 / 2000) x 0.01 = 3.2e-4 rad rms, 11x the
    # position floor.
    "control_outliers_rd": ({"benchgen": ["-e", "outliers:rate=2,size=0.01,channel=rd"]}, ("const", "oab3"),
                            "resolver-sim puts spikes on the sin channel only"),
    # alpha(t) = 0.003 + 1e-3 t: over the 3 s bench alpha goes 0.003 -> 0.006; the fit takes
    # the mean, so the 2 theta ripple (alpha/2) is off by up to 1.5e-3 / 2 = 7.5e-4 rad at the
    # ends, ~30x the floor, and no catalog effect depends on time.
    "control_alpha_drift": ({"sim": ["--alpha-drift", "0.001"],
                             "benchgen": ["-e", "alpha_drift:rate=1e-3"]}, ("const", "angle1"), ""),
}

# Checks expected to fail: (case:check patterns, reason). Both generators agree on each
# (the physics, not a generator), so the patterns start with "*". The lead removes an
# entry when the core is fixed; an entry none of whose checks fails is reported as XPASS
# and fails the test.
XFAIL = [
    # Expected failures, each with its named reason. None is open: the ones this matrix
    # found (mounting offset's winding frame, delay across speed steps, ranking's
    # alike(), backlash's take-up, the model-reference split, sin/cos outliers, the
    # drift's suggested block) are fixed; a new one goes here with the command that shows it.
    # The streaming path's (run_hidden_effect.py --streaming, issue 23) are fixed too: a
    # nonlinear merge relinearised over passes (mounting_offset/reversals), a chunk going on
    # from where the last left the rotor (backlash's take-up), every proposed candidate
    # refitted offline (envelope_drift's one step was 6 se from its fit in memory).
]
