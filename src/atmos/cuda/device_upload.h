// atmos: device copies of an evaluator (nvcc only).
//
// ToDevice(evaluator, &tables) returns a copy of the evaluator that the device
// can use: evaluators without host pointers are copied as they are (they are
// trivially copyable values); evaluators with lookup tables get each
// TableView re-pointed to a device copy held by `tables` (alive for the
// render). A model with tables adds its overload here.
#pragma once

#include <type_traits>

#include "cuda/device_buffer.h"
#include "models/atmosphere_plus.h"
#include "models/bruneton.h"
#include "models/hillaire.h"

namespace atmos::cuda {

template <typename Evaluator>
Evaluator ToDevice(const Evaluator& evaluator, DeviceTables*) {
    static_assert(std::is_trivially_copyable<Evaluator>::value,
                  "evaluators are passed to kernels by value");
    return evaluator;
}

// Bruneton (seed 004): transmittance, irradiance, scattering and (separate
// storage) single Mie tables.
inline BrunetonEvaluator ToDevice(const BrunetonEvaluator& evaluator, DeviceTables* tables) {
    BrunetonEvaluator d = evaluator;
    d.lut.transmittance_table = tables->Upload(evaluator.lut.transmittance_table);
    d.lut.irradiance_table = tables->Upload(evaluator.lut.irradiance_table);
    d.lut.scattering_table = tables->Upload(evaluator.lut.scattering_table);
    d.lut.single_mie_table = tables->Upload(evaluator.lut.single_mie_table);
    return d;
}

// Hillaire: the fixed tables and this frame's sky-view / aerial-perspective
// tables (absent ones keep data == nullptr).
inline HillaireEvaluator ToDevice(const HillaireEvaluator& evaluator, DeviceTables* tables) {
    HillaireEvaluator d = evaluator;
    d.transmittance = tables->Upload(evaluator.transmittance);
    d.multiple_scattering = tables->Upload(evaluator.multiple_scattering);
    d.sky_view = tables->Upload(evaluator.sky_view);
    d.ap_scatter = tables->Upload(evaluator.ap_scatter);
    d.ap_transmittance = tables->Upload(evaluator.ap_transmittance);
    return d;
}

// Atmosphere Plus (seed 000): scattering and transmittance tables.
inline AtmospherePlusEvaluator ToDevice(const AtmospherePlusEvaluator& evaluator,
                                        DeviceTables* tables) {
    AtmospherePlusEvaluator d = evaluator;
    d.scattering = tables->Upload(evaluator.scattering);
    d.transmittance = tables->Upload(evaluator.transmittance);
    return d;
}

}  // namespace atmos::cuda
