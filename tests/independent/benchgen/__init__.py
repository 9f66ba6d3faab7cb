"""benchgen: an independent resolver-bench log generator.

Written from docs/ARCHITECTURE.md (§3, §4, §7), Hanselman 1991 and Hwang 2009,
NOT from the project's C++ effect code, so that a sign slip shared by resolver-sim and the
fit cannot pass every test. Data flow, one function per stage:

    profile.MotionProfile      theta_m(t), omega_m(t): exact integral of piecewise-linear speed
    mechanics.ResolverShaft    angle the resolver rotor sees: backlash play, mounting offset,
                               eccentricity, mechanical harmonics
    windings.Windings          unit-amplitude sin/cos envelopes S(theta), C(theta): imbalance,
                               quadrature, offsets, inductance harmonics (Hanselman eq. 8)
    chain.SensorChain          analog signals in time: channel delay, dead channel, controls
    converter                  R/D converter: ideal atan2 or the nonlinear type-II loop (RK4)
    currents                   phase currents from the commanded i_d/i_q in the drive frame
    bench.simulate             samples at t_k = k / fs: DSP sin/cos [counts], R/D angle,
                               reference angle, phase currents, with noise and impairments
    layouts / writers          candump -l, Vector ASC, scope-style CSV, truth JSON/CSV

Everything is deterministic for a given seed: each random source draws from its own child
of numpy.random.SeedSequence(seed), so adding one impairment never changes another's draws.
"""
