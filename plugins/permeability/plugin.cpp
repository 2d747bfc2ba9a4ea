// The built-in permeability plugin library: its info record and entry point.
#include "frostmpm/plugin/plugin_api.hpp"

FROSTMPM_PLUGIN("frostmpm-permeability", "0.1.0")
