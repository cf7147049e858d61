# Generates the C++ table of the published MERL materials from a TSV file (name, sha256, size).
# Usage: cmake -DIN=merl_sha256.tsv -DOUT=merl_table.cpp -P embed_merl_table.cmake
# Fails on a malformed row, so that a bad table never reaches the library.
file(STRINGS "${IN}" lines)
list(LENGTH lines n)
if(n LESS 2)
  message(FATAL_ERROR "${IN}: no data rows")
endif()
list(GET lines 0 header)
if(NOT header STREQUAL "material\tsha256\tsize")
  message(FATAL_ERROR "${IN}: unexpected header '${header}' (expected: material<TAB>sha256<TAB>size)")
endif()
list(REMOVE_AT lines 0)
set(rows "")
set(count 0)
set(line_no 1)
foreach(line IN LISTS lines)
  math(EXPR line_no "${line_no} + 1")
  if(line STREQUAL "")
    continue()
  endif()
  string(REPLACE "\t" ";" fields "${line}")
  list(LENGTH fields nf)
  if(NOT nf EQUAL 3)
    message(FATAL_ERROR "${IN}:${line_no}: expected 3 tab-separated fields, got ${nf}")
  endif()
  list(GET fields 0 name)
  list(GET fields 1 sha)
  list(GET fields 2 size)
  if(NOT name MATCHES "^[A-Za-z0-9._-]+$")
    message(FATAL_ERROR "${IN}:${line_no}: bad material name '${name}'")
  endif()
  if(NOT sha MATCHES "^[0-9a-f]+$")
    message(FATAL_ERROR "${IN}:${line_no}: sha256 '${sha}' is not lowercase hex")
  endif()
  string(LENGTH "${sha}" sha_len)
  if(NOT sha_len EQUAL 64)
    message(FATAL_ERROR "${IN}:${line_no}: sha256 has ${sha_len} hex digits, expected 64")
  endif()
  if(NOT size MATCHES "^[0-9]+$")
    message(FATAL_ERROR "${IN}:${line_no}: size '${size}' is not a number")
  endif()
  string(APPEND rows "    {\"${name}\", \"${sha}\", ${size}u},\n")
  math(EXPR count "${count} + 1")
endforeach()
file(WRITE "${OUT}.tmp"
"// Generated from ${IN} by cmake/embed_merl_table.cmake. Do not edit.
#include \"halfback/formats/merl.hpp\"

namespace halfback::merl_table {
extern const MerlMaterial kMaterials[];
extern const std::size_t kMaterialCount;
const MerlMaterial kMaterials[] = {
${rows}};
const std::size_t kMaterialCount = ${count};
}  // namespace halfback::merl_table
")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.tmp")
