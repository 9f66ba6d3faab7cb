// Effect: R/D converter quantization.
//
// The converter reports its angle with rd_bits of resolution. On the bench CAN
// layout (docs/ARCHITECTURE.md §4) the angle travels in a u16 (65536 counts = 2pi resolver
// electrical rad) whose low (16 - rd_bits) bits are zero.
// Forward model: round phi to the nearest multiple of LSB = 2pi / 2^rd_bits.
// Signature: eps_q = phi - q(phi), uniform in [-LSB/2, +LSB/2] for a moving
// angle, RMS LSB / sqrt(12).
#pragma once

#include <array>
#include <cstdint>

#include "daemon/core/effects/param_set.h"

namespace resolver {

/// [bits] the u16 rd_angle field's own resolution (docs/ARCHITECTURE.md §4): a
/// converter this fine adds no quantization, so it is also rd_bits' largest and neutral value.
inline constexpr int kRdFieldBits = 16;

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kQuantizationParams{
    ParamInfo{.name = "rd_bits", .unit = "[bits]", .description = "R/D converter resolution", .min = 1,
              .max = kRdFieldBits, .neutral = kRdFieldBits, .integer = true},
};
using QuantizationParams = ParamSet<kQuantizationParams>;

/// One LSB of an rd_bits converter [rad]. rd_bits must be in its listed range (not checked here).
[[nodiscard]] double quantization_lsb(int rd_bits);

/// Rounds phi [rad, any range] to rd_bits and returns the u16 field value
/// (0..65535 = 0..2pi, low 16 - rd_bits bits zero). rd_bits must be in its listed range.
[[nodiscard]] std::uint16_t quantize_rd_angle(double phi, int rd_bits);

/// The angle [rad] in [0, 2pi) a u16 rd_angle field value stands for.
[[nodiscard]] double rd_counts_to_angle(std::uint16_t counts);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& quantization_effect();

}  // namespace resolver
