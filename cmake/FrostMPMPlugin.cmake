# frostmpm_add_plugin(<target> SOURCES <files...> [OUTPUT_DIR <dir>] [INSTALL])
# Builds a FrostMPM model/physics plugin: a shared library with hidden visibility that links
# the core library. Used by the in-tree plugins and by third parties through find_package(FrostMPM).
function(frostmpm_add_plugin target)
  cmake_parse_arguments(ARG "INSTALL" "OUTPUT_DIR" "SOURCES;LIBRARIES" ${ARGN})
  add_library(${target} MODULE ${ARG_SOURCES})
  if(TARGET FrostMPM::core)
    target_link_libraries(${target} PRIVATE FrostMPM::core ${ARG_LIBRARIES})
  else()
    target_link_libraries(${target} PRIVATE frostmpm_core ${ARG_LIBRARIES})
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX "lib"
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIR})
  endif()
  if(ARG_INSTALL AND DEFINED FROSTMPM_PLUGIN_SUBDIR)
    install(TARGETS ${target} LIBRARY DESTINATION ${FROSTMPM_PLUGIN_SUBDIR})
  endif()
endfunction()
