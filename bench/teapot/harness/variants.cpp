#include "harness/variant.hpp"

namespace teapot {

const std::vector<VariantEntry>& variant_registry() {
    // raw-direct is the reference the ratios and image checks use;
    // raw-direct-control is a second copy of it, the A/A control.
    static const std::vector<VariantEntry> registry = {
        {"raw-direct", make_raw_direct_variant},
        {"raw-direct-control", make_raw_direct_variant},
        {"raw", make_raw_variant},
        {"vkhpp", make_vkhpp_variant},
#if TEAPOT_HAS_VKRC_ST
        {"vkrc-st", make_vkrc_st_variant},
#endif
#if TEAPOT_HAS_VKRC_ST_CHECKED
        {"vkrc-st-checked", make_vkrc_st_checked_variant},
#endif
#if TEAPOT_HAS_VKRC_MT
        {"vkrc-mt", make_vkrc_mt_variant},
#endif
    };
    return registry;
}

}  // namespace teapot
