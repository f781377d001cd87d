# Warnings and sanitizers in one place, applied per target (never globally).

function(priormap_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
                                           -Wnull-dereference -Wformat=2 -Wimplicit-fallthrough)
  if(PRIORMAP_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

function(priormap_set_sanitizers target)
  if(PRIORMAP_SANITIZE)
    list(JOIN PRIORMAP_SANITIZE "," sanitizers)
    target_compile_options(${target} PRIVATE -fsanitize=${sanitizers} -fno-omit-frame-pointer
                                             -fno-sanitize-recover=all)
    target_link_options(${target} PRIVATE -fsanitize=${sanitizers})
  endif()
endfunction()

# Every first-party target goes through here: C++20, warnings, sanitizers.
function(priormap_configure_target target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
  priormap_set_warnings(${target})
  priormap_set_sanitizers(${target})
endfunction()

option(PRIORMAP_WARNINGS_AS_ERRORS "Treat compiler warnings as errors" OFF)
