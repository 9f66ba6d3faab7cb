// The default bench CAN layout (docs/ARCHITECTURE.md §4), as constants and an encoder.
//
// The daemon decodes frames through proto/resolver_bench.dbc (so a user's own
// layout is only a different DBC + signal map). This header is the second,
// independent description of the same layout: the simulator encodes with it and
// the tests check that the DBC decodes what this encodes.
//
//  ID     name              bytes (little endian)
//  0x100  RESOLVER_SAMPLE   0 counter u8 | 1-2 sin i16 | 3-4 cos i16 | 5-6 rd_angle u16 | 7 crc
//  0x101  PHASE_CURRENTS    0 counter u8 | 1-2 i_a i16 | 3-4 i_b i16 | 5-6 i_c i16 [mA] | 7 crc
//  0x102  REFERENCE_ANGLE   0 counter u8 | 1-4 ref_angle u32 (2^32 = 2pi mech) | 5-6 0 | 7 crc
//  0x1F0  BENCH_INFO        0 version=1 | 1 p_r | 2 p | 3 rd_bits | 4-5 sample_rate_hz u16 | 6 0 | 7 crc
#pragma once

#include <cstdint>

#include "daemon/decode/crc8_j1850.h"
#include "drivers/can_frame.h"

namespace resolver::bench {

inline constexpr std::uint32_t kIdResolverSample = 0x100;
inline constexpr std::uint32_t kIdPhaseCurrents = 0x101;
inline constexpr std::uint32_t kIdReferenceAngle = 0x102;
inline constexpr std::uint32_t kIdBenchInfo = 0x1F0;
inline constexpr std::uint8_t kLayoutVersion = 1;
inline constexpr std::uint8_t kFrameLen = 8;

/// ADC full scale of the sin/cos envelopes [counts] (i16, +-32767).
inline constexpr double kSinCosFullScale = 32767.0;
/// Phase current scaling [A per bit] (1 mA/bit).
inline constexpr double kCurrentAmpsPerBit = 1e-3;
/// rd_angle: 0..65535 = 0..2pi resolver electrical rad.
inline constexpr double kRdAngleCounts = 65536.0;
/// ref_angle: 0..2^32 = 0..2pi mechanical rad.
inline constexpr double kRefAngleCounts = 4294967296.0;

namespace detail {
inline void put_u16(CanFrame& f, int at, std::uint16_t v) {
  f.data[static_cast<std::size_t>(at)] = static_cast<std::uint8_t>(v & 0xFFU);
  f.data[static_cast<std::size_t>(at) + 1] = static_cast<std::uint8_t>(v >> 8U);
}
inline void put_u32(CanFrame& f, int at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) {
    f.data[static_cast<std::size_t>(at) + i] = static_cast<std::uint8_t>((v >> (8U * i)) & 0xFFU);
  }
}
inline CanFrame start(std::uint32_t id, std::int64_t t_us) {
  CanFrame f;
  f.id = id;
  f.len = kFrameLen;
  f.timestamp_us = t_us;
  return f;
}
inline void seal(CanFrame& f) { f.data[7] = bench_frame_crc(f.data.data(), f.id); }
}  // namespace detail

/// RESOLVER_SAMPLE. sin/cos in ADC counts; rd_angle in counts of 2pi/65536.
inline CanFrame encode_resolver_sample(std::int64_t t_us, std::uint8_t counter, std::int16_t sin_counts,
                                       std::int16_t cos_counts, std::uint16_t rd_angle_counts) {
  CanFrame f = detail::start(kIdResolverSample, t_us);
  f.data[0] = counter;
  detail::put_u16(f, 1, static_cast<std::uint16_t>(sin_counts));
  detail::put_u16(f, 3, static_cast<std::uint16_t>(cos_counts));
  detail::put_u16(f, 5, rd_angle_counts);
  detail::seal(f);
  return f;
}

/// PHASE_CURRENTS in mA.
inline CanFrame encode_phase_currents(std::int64_t t_us, std::uint8_t counter, std::int16_t i_a_ma,
                                      std::int16_t i_b_ma, std::int16_t i_c_ma) {
  CanFrame f = detail::start(kIdPhaseCurrents, t_us);
  f.data[0] = counter;
  detail::put_u16(f, 1, static_cast<std::uint16_t>(i_a_ma));
  detail::put_u16(f, 3, static_cast<std::uint16_t>(i_b_ma));
  detail::put_u16(f, 5, static_cast<std::uint16_t>(i_c_ma));
  detail::seal(f);
  return f;
}

/// REFERENCE_ANGLE: mechanical angle in counts of 2pi/2^32.
inline CanFrame encode_reference_angle(std::int64_t t_us, std::uint8_t counter, std::uint32_t ref_counts) {
  CanFrame f = detail::start(kIdReferenceAngle, t_us);
  f.data[0] = counter;
  detail::put_u32(f, 1, ref_counts);
  detail::seal(f);
  return f;
}

/// BENCH_INFO (sent at 10 Hz).
inline CanFrame encode_bench_info(std::int64_t t_us, std::uint8_t p_r, std::uint8_t p, std::uint8_t rd_bits,
                                  std::uint16_t sample_rate_hz) {
  CanFrame f = detail::start(kIdBenchInfo, t_us);
  f.data[0] = kLayoutVersion;
  f.data[1] = p_r;
  f.data[2] = p;
  f.data[3] = rd_bits;
  detail::put_u16(f, 4, sample_rate_hz);
  detail::seal(f);
  return f;
}

}  // namespace resolver::bench
