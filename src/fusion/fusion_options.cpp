// Options of the fusion (see fusion_options.hpp).

#include "canyon/fusion/fusion_options.hpp"

namespace canyon::fusion {

std::string FusionOptions::validate() const {
  if (const std::string e = time_sync.validate(); !e.empty()) return "time_sync: " + e;
  if (const std::string e = vio.validate(); !e.empty()) return "vio: " + e;
  for (const std::string& e :
       {alignment.validate(), cn0.validate(), coarse.validate(), integrity.validate(), heading.validate(),
        gates.validate(), recovery.validate(), guard.validate(), validation.validate(), output_floor.validate()}) {
    if (!e.empty()) return e;
  }
  if (!(prediction.constant_increment_sigma_m > 0.0)) return "constant_increment_sigma_m must be > 0";
  if (!(prediction.vio_sigma_factor >= 1.0)) return "vio_sigma_factor must be >= 1";
  if (!(prediction.vio_scale_sigma > 0.0 && prediction.vio_scale_sigma < 0.5) ||
      !(prediction.vio_scale_random_walk_per_sqrt_km >= 0.0)) {
    return "vio_scale_sigma must be in (0, 0.5) and vio_scale_random_walk_per_sqrt_km >= 0";
  }
  if (!(vio_keep_s > 0.0)) return "vio_keep_s must be > 0";
  return {};
}

}  // namespace canyon::fusion
