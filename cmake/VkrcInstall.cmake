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

set(vkrc_install_targets "")
foreach(policy IN LISTS VKRC_POLICIES)
  list(APPEND vkrc_install_targets vkrc_${policy})
endforeach()
# Add-on libraries join the same export set when they are built; each one's
# EXPORT_NAME gives its imported name (vkrc_glfw_st -> vkrc::glfw_st). Their
# dependencies are found in vkrcConfig.cmake.in, next to Vulkan's.
set(VKRC_INSTALLED_GLFW OFF)
foreach(policy IN LISTS VKRC_POLICIES)
  if(TARGET vkrc_glfw_${policy})
    list(APPEND vkrc_install_targets vkrc_glfw_${policy})
    set(VKRC_INSTALLED_GLFW ON)
  endif()
endforeach()

install(TARGETS ${vkrc_install_targets}
  EXPORT vkrcTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The whole directory, so headers added later need no change here.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/vkrc DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT vkrcTargets
  NAMESPACE vkrc::
  FILE vkrcTargets.cmake
  DESTINATION ${VKRC_INSTALL_CMAKEDIR})

# The policies and add-ons this installation holds, for vkrcConfig.cmake.
set(VKRC_INSTALLED_POLICIES "${VKRC_POLICIES}")
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
install(FILES
  ${PROJECT_BINARY_DIR}/vkrcConfig.cmake
  ${PROJECT_BINARY_DIR}/vkrcConfigVersion.cmake
  DESTINATION ${VKRC_INSTALL_CMAKEDIR})
