# phyxel_add_shaders(<target> SHADERS <file.comp>... [INCLUDE_DIRS <dir>...])
#
# Compiles each GLSL shader at build time with glslangValidator (--target-env vulkan1.2) into
# a C header holding the SPIR-V words, and makes <target> depend on it:
#
#   <binary dir of the calling CMakeLists>/phyxel_spv/<name>.spv.h
#     const uint32_t phyxel_spv_<name>[] = {...};   (<name>: file name without the extension,
#                                                    '.' and '-' turned into '_')
#
# The folder holding the generated headers is added to <target>'s PRIVATE include path, so a
# source of <target> writes `#include "phyxel_spv/fill.spv.h"` (after <cstdint>). Included GLSL
# headers are tracked through glslangValidator's depfile; the directory of each shader and the
# INCLUDE_DIRS are on the GLSL include path. SPIR-V is never checked in.
include_guard(GLOBAL)

find_program(PHYXEL_GLSLANG_VALIDATOR glslangValidator REQUIRED
             DOC "glslangValidator (Debian package glslang-tools)")

function(phyxel_add_shaders target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "SHADERS;INCLUDE_DIRS")
  if(NOT ARG_SHADERS)
    message(FATAL_ERROR "phyxel_add_shaders(${target}): no SHADERS given")
  endif()
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/phyxel_spv)
  set(include_flags)
  foreach(dir ${ARG_INCLUDE_DIRS})
    get_filename_component(dir ${dir} ABSOLUTE)
    list(APPEND include_flags -I${dir})
  endforeach()
  set(headers)
  foreach(shader ${ARG_SHADERS})
    get_filename_component(src ${shader} ABSOLUTE)
    get_filename_component(src_dir ${src} DIRECTORY)
    get_filename_component(name ${src} NAME_WE)
    string(MAKE_C_IDENTIFIER ${name} ident)
    set(header ${out_dir}/${name}.spv.h)
    add_custom_command(
      OUTPUT ${header}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${out_dir}
      COMMAND ${PHYXEL_GLSLANG_VALIDATOR} --quiet --target-env vulkan1.2 -I${src_dir}
              ${include_flags} --vn phyxel_spv_${ident} --depfile ${header}.d -o ${header} ${src}
      MAIN_DEPENDENCY ${src}
      DEPFILE ${header}.d
      COMMENT "glslangValidator ${name}"
      VERBATIM)
    list(APPEND headers ${header})
  endforeach()
  target_sources(${target} PRIVATE ${headers})
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_BINARY_DIR})
endfunction()
