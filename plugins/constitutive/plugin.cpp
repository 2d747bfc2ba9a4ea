// The built-in constitutive-model plugin library (kind mechanical_model): its info record and
// entry point.
#include "frostmpm/plugin/plugin_api.hpp"

FROSTMPM_PLUGIN("frostmpm-constitutive", "0.1.0")
