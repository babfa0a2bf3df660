# gi_add_effect(<name> SOURCES <c++ files> [SHADERS <glsl files>])
#
# Builds an effect plugin as a shared module `gi_effect_<name>.so` that the registry loads at
# run time. Each shader is compiled (and validated) by glslangValidator at build time into a
# header `<file>.h` (e.g. `ssao.comp.h`) holding `const uint32_t <file_with_underscores>[]`
# (e.g. `ssao_comp`), so a module is one self-contained file. The header also registers the
# words with the engine together with the source file's absolute path
# (gi/vk/shader_overrides.h), so a tool such as gi-demo can hot-reload the GLSL. Shaders may
# `#include "common.glsl"` (the engine's FrameUniforms and helpers), "environment.glsl"
# (environment importance sampling) and "lights.glsl" (lights and shadow maps).
#
# Works in the engine's own tree and against an installed package (find_package(gi), which
# includes this file and sets GI_SHADER_INCLUDE_DIR). GI_PLUGIN_OUTPUT_DIR sets where modules
# land (default: <build>/plugins; point GI_PLUGIN_PATH there to run them). See effects/README.md.

find_program(GI_GLSLANG_VALIDATOR glslangValidator)

function(gi_add_effect name)
  cmake_parse_arguments(EFFECT "" "" "SOURCES;SHADERS" ${ARGN})
  if(NOT EFFECT_SOURCES)
    message(FATAL_ERROR "gi_add_effect(${name}): SOURCES is required")
  endif()
  if(EFFECT_SHADERS AND NOT GI_GLSLANG_VALIDATOR)
    message(FATAL_ERROR "gi_add_effect(${name}): glslangValidator not found (Debian: glslang-tools)")
  endif()
  if(NOT GI_SHADER_INCLUDE_DIR)
    message(FATAL_ERROR "gi_add_effect(${name}): GI_SHADER_INCLUDE_DIR is not set (find_package(gi) sets it)")
  endif()
  set(target gi_effect_${name})
  add_library(${target} MODULE ${EFFECT_SOURCES})
  if(NOT GI_PLUGIN_OUTPUT_DIR)
    set(GI_PLUGIN_OUTPUT_DIR ${CMAKE_BINARY_DIR}/plugins)
  endif()
  set_target_properties(${target} PROPERTIES PREFIX "" OUTPUT_NAME ${target}
    LIBRARY_OUTPUT_DIRECTORY ${GI_PLUGIN_OUTPUT_DIR}
    CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON CXX_VISIBILITY_PRESET hidden)
  target_link_libraries(${target} PRIVATE gi::engine)
  set_property(GLOBAL APPEND PROPERTY GI_EFFECT_TARGETS ${target})

  set(generated ${CMAKE_CURRENT_BINARY_DIR}/${target}_shaders)
  file(GLOB includes ${GI_SHADER_INCLUDE_DIR}/*.glsl)  # a changed include rebuilds the shaders
  set(headers)
  # Appends the registration to a generated header: the words with their source file, so a
  # tool can hot-reload them (one registration per translation unit; the engine finds a
  # shader by its words' content).
  set(register ${CMAKE_BINARY_DIR}/gi_register_shader.cmake)
  file(CONFIGURE OUTPUT ${register} CONTENT [=[
file(APPEND ${HEADER} "
#include \"gi/vk/shader_overrides.h\"
static const gi::vk::ShaderRegistration ${VARIABLE}_registration{
    ${VARIABLE}, sizeof(${VARIABLE}) / sizeof(${VARIABLE}[0]), \"${SOURCE}\", \"${INCLUDE_DIR}\"};
")
]=] @ONLY)
  foreach(shader ${EFFECT_SHADERS})
    get_filename_component(file ${shader} NAME)
    get_filename_component(source ${shader} ABSOLUTE)
    string(REPLACE "." "_" variable ${file})
    set(header ${generated}/${file}.h)
    add_custom_command(OUTPUT ${header}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${generated}
      COMMAND ${GI_GLSLANG_VALIDATOR} --quiet --target-env vulkan1.3 -I${GI_SHADER_INCLUDE_DIR}
              --vn ${variable} -o ${header} ${source}
      COMMAND ${CMAKE_COMMAND} -DHEADER=${header} -DVARIABLE=${variable} -DSOURCE=${source}
              -DINCLUDE_DIR=${GI_SHADER_INCLUDE_DIR} -P ${register}
      DEPENDS ${source} ${includes} ${register}
      COMMENT "GLSL ${name}/${file}" VERBATIM)
    list(APPEND headers ${header})
  endforeach()
  if(headers)
    target_sources(${target} PRIVATE ${headers})
    target_include_directories(${target} PRIVATE ${generated})
  endif()
endfunction()
