# priormap_add_module(<name> <sources>...): the library priormap_<name> of one module, with its
# alias priormap::<name>, export name, warnings and sanitizers, and the public include directory.
# Each module links its own dependencies.
function(priormap_add_module name)
  set(target priormap_${name})
  add_library(${target} ${ARGN})
  add_library(priormap::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME ${target})
  priormap_configure_target(${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
endfunction()
