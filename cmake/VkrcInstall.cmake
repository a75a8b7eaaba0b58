# Install rules and the CMake package, so that a consumer writes
#     find_package(vkrc CONFIG REQUIRED)
#     target_link_libraries(app PRIVATE vkrc::vkrc)   # or vkrc::st / vkrc::mt
# Included from the top-level CMakeLists.txt after every vkrc library target
# is defined. Installs whichever policy libraries VKRC_POLICIES built.
# Does nothing with VKRC_INSTALL off (the default under add_subdirectory and
# FetchContent, where the parent project decides what it installs).
if(NOT VKRC_INSTALL)
  return()
endif()
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(VKRC_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/vkrc" CACHE STRING
    "Where the vkrc CMake package files are installed, relative to the prefix")

# One export set and one install component per policy (st, mt: the library,
# its add-ons and vkrcTargets-<policy>.cmake), and the component "common"
# (headers, package files, shader helper), so that an installation may hold
# only one policy: cmake --install <build> --component common, then
# --component mt. vkrcConfig.cmake includes the vkrcTargets-*.cmake it finds.
# Add-on libraries (vkrc_glfw_<policy>, EXPORT_NAME glfw_<policy>) join their
# policy's set when they are built; vkrcConfig.cmake finds their dependencies.
foreach(policy IN LISTS VKRC_POLICIES)
  set(targets vkrc_${policy})
  if(TARGET vkrc_glfw_${policy})
    list(APPEND targets vkrc_glfw_${policy})
  endif()
  install(TARGETS ${targets}
    EXPORT vkrcTargets-${policy}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT ${policy}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT vkrcTargets-${policy}
    NAMESPACE vkrc::
    FILE vkrcTargets-${policy}.cmake
    DESTINATION ${VKRC_INSTALL_CMAKEDIR}
    COMPONENT ${policy})
endforeach()
# The whole directory, so headers added later need no change here.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/vkrc DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT common)
# The generated extension function list (vkrc/extension_functions.hpp includes it).
install(DIRECTORY ${VKRC_GENERATED_DIR}/include/vkrc DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT common)

configure_package_config_file(
  ${CMAKE_CURRENT_LIST_DIR}/vkrcConfig.cmake.in
  ${PROJECT_BINARY_DIR}/vkrcConfig.cmake
  INSTALL_DESTINATION ${VKRC_INSTALL_CMAKEDIR})
# While vkrc is 0.x a minor release may break the API (semantic versioning),
# so find_package(vkrc 0.1) accepts 0.1.x only; from 1.0 this becomes
# SameMajorVersion.
write_basic_package_version_file(
  ${PROJECT_BINARY_DIR}/vkrcConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
# vkrc_add_shaders for find_package users: vkrcConfig.cmake includes it.
install(FILES
  ${PROJECT_BINARY_DIR}/vkrcConfig.cmake
  ${PROJECT_BINARY_DIR}/vkrcConfigVersion.cmake
  ${CMAKE_CURRENT_LIST_DIR}/VkrcShaders.cmake
  ${CMAKE_CURRENT_LIST_DIR}/VkrcShaderWrap.cmake
  DESTINATION ${VKRC_INSTALL_CMAKEDIR}
  COMPONENT common)
