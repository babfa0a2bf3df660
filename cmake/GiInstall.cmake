# Installs the engine as a CMake package (find_package(gi) -> gi::engine, gi::scene,
# gi_add_effect, GI_SHADER_INCLUDE_DIR) together with the four apps, their SPIR-V, the in-tree
# effect modules, the presets, the scenes with the models they use and the example demo script:
#
#   <prefix>/bin/gi-render, gi-demo,     <prefix>/include/gi/...
#       gi-bench, gi-reference           <prefix>/share/gi/shaders/*.glsl (effect includes)
#   <prefix>/bin/shaders/*.spv           <prefix>/share/gi/presets/*.json
#   <prefix>/bin/plugins/gi_effect_*.so  <prefix>/share/gi/scenes/*.json, models/, environments/
#   <prefix>/<libdir>/libgi_engine.so,   <prefix>/share/gi/scripts/*.txt (gi-demo --script)
#       libgi_scene.so, libgi_config.so
#   <prefix>/<libdir>/cmake/gi/giConfig.cmake, giConfigVersion.cmake, giTargets.cmake,
#                              GiEffect.cmake
#
# The apps find their shaders, plugins and presets relative to their own location, scenes name
# their models relative to themselves (../models/...), and every binary finds the libraries
# through a relative RPATH, so the prefix can be moved (`cmake --install build --prefix /x`).
# Included by the top-level CMakeLists.txt after the engine, apps and effects exist.

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(GI_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/gi)
set(GI_INSTALL_SHADERDIR ${CMAKE_INSTALL_DATADIR}/gi/shaders)

# Relative RPATHs: bin/ -> libdir, bin/plugins/ -> libdir.
file(RELATIVE_PATH gi_bin_to_lib /prefix/bin /prefix/${CMAKE_INSTALL_LIBDIR})
file(RELATIVE_PATH gi_plugins_to_lib /prefix/bin/plugins /prefix/${CMAKE_INSTALL_LIBDIR})
set_target_properties(gi_scene gi_config gi_engine PROPERTIES INSTALL_RPATH "$ORIGIN")
# Exported as gi::scene, gi::config and gi::engine, the names the build tree's aliases use.
set_target_properties(gi_scene PROPERTIES EXPORT_NAME scene)
set_target_properties(gi_config PROPERTIES EXPORT_NAME config)
set_target_properties(gi_engine PROPERTIES EXPORT_NAME engine)
set(GI_INSTALLED_APPS gi-render gi-bench gi-reference)
if(TARGET gi-demo)
  list(APPEND GI_INSTALLED_APPS gi-demo)
endif()
set_target_properties(${GI_INSTALLED_APPS} PROPERTIES INSTALL_RPATH "$ORIGIN/${gi_bin_to_lib}")

install(TARGETS gi_scene gi_config gi_engine EXPORT giTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/engine/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${CMAKE_SOURCE_DIR}/engine/shaders/common.glsl
  ${CMAKE_SOURCE_DIR}/engine/shaders/environment.glsl
  ${CMAKE_SOURCE_DIR}/engine/shaders/lights.glsl
  ${CMAKE_SOURCE_DIR}/engine/shaders/depth_aware_blur.glsl
  ${CMAKE_SOURCE_DIR}/engine/shaders/normal_codec.glsl
  ${CMAKE_SOURCE_DIR}/engine/shaders/gbuffer.glsl DESTINATION ${GI_INSTALL_SHADERDIR})
install(EXPORT giTargets NAMESPACE gi:: DESTINATION ${GI_INSTALL_CMAKEDIR})

# The executables keep the layout of the build tree (bin/, bin/shaders, bin/plugins,
# share/gi/presets) because they look for those next to themselves.
install(TARGETS ${GI_INSTALLED_APPS} RUNTIME DESTINATION bin)
install(DIRECTORY ${CMAKE_BINARY_DIR}/bin/shaders/ DESTINATION bin/shaders
  FILES_MATCHING PATTERN "*.spv")
if(GI_PRESETS)
  install(FILES ${GI_PRESETS} DESTINATION share/gi/presets)
endif()
# Scenes keep their folder beside models/ and environments/: they name those files relatively.
foreach(dir scenes models environments scripts)
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/assets/${dir} DESTINATION share/gi)
endforeach()
get_property(gi_effect_targets GLOBAL PROPERTY GI_EFFECT_TARGETS)
if(gi_effect_targets)
  set_target_properties(${gi_effect_targets} PROPERTIES INSTALL_RPATH "$ORIGIN/${gi_plugins_to_lib}")
  install(TARGETS ${gi_effect_targets} LIBRARY DESTINATION bin/plugins)
endif()

configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/giConfig.cmake.in
  ${CMAKE_BINARY_DIR}/cmake/giConfig.cmake
  INSTALL_DESTINATION ${GI_INSTALL_CMAKEDIR}
  PATH_VARS GI_INSTALL_SHADERDIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/cmake/giConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/giConfig.cmake
  ${CMAKE_BINARY_DIR}/cmake/giConfigVersion.cmake ${CMAKE_SOURCE_DIR}/cmake/GiEffect.cmake
  DESTINATION ${GI_INSTALL_CMAKEDIR})
