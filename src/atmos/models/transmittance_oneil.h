// atmos model `transmittance-oneil`: the view ray's transmittance from O'Neil's
// fitted scale() optical depth.
//
// Source: O'Neil 2005 (GPU Gems 2 ch. 16), Raush's O'Neil slides (2018), Leenman's 2025 thesis
// Eq. 17. Implements: OneilOptics::SegmentDepth of models/oneil.h (scale() per medium, refitted in
// Prepare() by default, `--fit original` for his constants and scale depth 0.25); T = exp(-tau). No
// ozone. Output: transmittance only.
#pragma once

#include "models/oneil.h"
#include "models/transmittance_common.h"

namespace atmos {

struct TransmittanceOneilOptions {
    bool refit = true;  // scale() refitted per medium (false: O'Neil's constants)
};

class TransmittanceOneilModel : public TransmittanceModel<TransmittanceOneilModel, OneilOptics> {
  public:
    static const OptionTable<TransmittanceOneilOptions>& OptionRows();
    explicit TransmittanceOneilModel(const TransmittanceOneilOptions& options);
    static ModelInfo StaticInfo();
    OneilOptics MakeOptics(const AtmosphereParameters& atmosphere) const {
        return MakeOneilOptics(atmosphere, refit_);
    }

  private:
    bool refit_ = true;
};

}  // namespace atmos
