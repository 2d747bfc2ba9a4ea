// The built-in SFCC plugin library: its info record and entry point.
#include "frostmpm/plugin/plugin_api.hpp"

FROSTMPM_PLUGIN("frostmpm-sfcc", "0.1.0")
