# Checks every #include of a source tree against the layer graph of docs/architecture.md, and the
# graph against the includes: a layer's library may include only what its line allows, its tests
# also what its tests line allows; a line names every layer its library includes (but the base,
# core, util and brdf, that a layer it names brings), and every layer a line names must be
# included directly by the files that line is for (a layer's own files: its library's, or its
# tests'), so that the graph links nothing that is not used.
#   cmake -DROOT=<tree> -DGRAPH=<docs/architecture.md> -P check_layers.cmake
# Fails listing each forbidden include as "file: \"include\": why", and each layer named but not
# used. tests/package (a project outside halfback) and tests/architecture (fixtures of this check)
# are not part of the tree checked.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/layers.cmake)
halfback_read_layers(${GRAPH})

# The layer of a file, from its path relative to ROOT ("" for files outside the layered folders).
function(layer_of rel out)
  set(layer "")
  if(rel MATCHES "^include/halfback/([a-z]+)/")
    set(layer ${CMAKE_MATCH_1})
  elseif(rel MATCHES "^src/([a-z]+)/")
    set(layer ${CMAKE_MATCH_1})
  elseif(rel MATCHES "^tests/support/")
    set(layer support)
  elseif(rel MATCHES "^tests/([a-z]+)/")
    set(layer ${CMAKE_MATCH_1})
  elseif(rel MATCHES "^(bench|fuzz)/")
    set(layer cli)
  endif()
  set(${out} ${layer} PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE files RELATIVE ${ROOT}
  ${ROOT}/include/*.hpp ${ROOT}/src/*.hpp ${ROOT}/src/*.cpp ${ROOT}/tests/*.hpp ${ROOT}/tests/*.cpp
  ${ROOT}/bench/*.cpp ${ROOT}/bench/*.hpp ${ROOT}/fuzz/*.cpp ${ROOT}/fuzz/*.hpp)
set(errors "")
set(checked 0)
foreach(rel IN LISTS files)
  layer_of(${rel} layer)
  if(layer STREQUAL "" OR rel MATCHES "^tests/(architecture|package)/")
    continue()
  endif()
  if(NOT DEFINED HALFBACK_LAYER_ALLOWED_${layer})
    list(APPEND errors "${rel}: folder of no layer '${layer}' (add it to the graph)")
    continue()
  endif()
  set(is_test FALSE)
  if(rel MATCHES "_test(_support)?\\.(cpp|hpp)$" OR rel MATCHES "^(tests|bench|fuzz)/")
    set(is_test TRUE)
  endif()
  # The files a line of the graph is for: the library's (support's own files count as its
  # library), or the tests'.
  set(kind LIB)
  set(allowed_var HALFBACK_LAYER_ALLOWED_${layer})
  if(is_test AND NOT layer STREQUAL "support")
    set(kind TEST)
    set(allowed_var HALFBACK_LAYER_TEST_ALLOWED_${layer})
  endif()
  set(HAS_${kind}_${layer} TRUE)
  file(STRINGS ${ROOT}/${rel} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]*)\".*$" "\\1" inc "${line}")
    math(EXPR checked "${checked} + 1")
    set(target "")
    if(inc MATCHES "\\.\\.")
      list(APPEND errors "${rel}: \"${inc}\": no '..' in includes (name the header by its layer)")
      continue()
    elseif(inc MATCHES "^halfback/([a-z]+)/")
      set(target ${CMAKE_MATCH_1})
    elseif(inc MATCHES "^support/")
      if(NOT is_test)
        list(APPEND errors "${rel}: \"${inc}\": test helpers only in tests, benchmarks and fuzzers")
        continue()
      endif()
      set(target support)
    elseif(inc MATCHES "^([a-z]+)/")
      set(target ${CMAKE_MATCH_1})
    elseif(NOT inc MATCHES "/")
      set(target ${layer})  # a header beside the file
    else()
      list(APPEND errors "${rel}: \"${inc}\": not a header of a layer")
      continue()
    endif()
    if(target STREQUAL "support" AND is_test)
      continue()  # every test may use the shared test helpers
    endif()
    list(APPEND USED_${kind}_${layer} ${target})
    # A library names every layer it uses directly, but for the base (core, util, brdf) that a
    # layer it names brings.
    if(kind STREQUAL "LIB" AND target IN_LIST ${allowed_var} AND NOT target STREQUAL layer
       AND NOT target IN_LIST HALFBACK_LAYER_DEPS_${layer} AND NOT target MATCHES "^(core|util|brdf|support)$")
      list(APPEND errors "${rel}: \"${inc}\": layer ${layer} uses ${target} directly: name it on its line")
    endif()
    if(NOT target IN_LIST ${allowed_var})
      string(REPLACE ";" " " allowed "${${allowed_var}}")
      list(APPEND errors
           "${rel}: \"${inc}\": layer ${layer} may not include layer ${target} (it may include: ${allowed})")
    endif()
  endforeach()
endforeach()
# Every layer a line names is used directly by the files the line is for (when the tree has any).
foreach(layer IN LISTS HALFBACK_LAYERS)
  if(HAS_LIB_${layer})
    foreach(dep IN LISTS HALFBACK_LAYER_DEPS_${layer})
      if(NOT dep IN_LIST USED_LIB_${layer})
        list(APPEND errors
             "layer ${layer} names ${dep}, which none of its library files include (remove it from its line)")
      endif()
    endforeach()
  endif()
  if(HAS_TEST_${layer})
    foreach(dep IN LISTS HALFBACK_LAYER_TEST_DEPS_${layer})
      if(NOT dep IN_LIST USED_TEST_${layer})
        list(APPEND errors
             "layer ${layer}'s tests line names ${dep}, which none of its tests include (remove it)")
      endif()
    endforeach()
  endif()
endforeach()
if(errors)
  list(JOIN errors "\n  " text)
  message(FATAL_ERROR "includes against the layer graph of docs/architecture.md:\n  ${text}")
endif()
message(STATUS "${checked} includes follow the layer graph")
