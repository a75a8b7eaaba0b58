# Builds and runs tests/consumer (a separate CMake project) against vkrc the
# two ways applications get it: find_package of an installation of this build
# tree (consumer.install, a fixture, installs it into consumer-prefix) and
# add_subdirectory of the source tree.
#
# Registered only in builds without sanitizers: what these tests check is the
# install layout, the package config and the exported targets, which sanitizer
# flags do not change, while the program the consumer runs is the test suite's
# first steps, which the sanitizer builds already run. Forwarding the flags
# would only add two more vkrc builds to each sanitizer configuration.
if(CMAKE_CXX_FLAGS MATCHES "-fsanitize")
  return()
endif()

# Lists travel as comma-separated words: a ';' would split the argument.
string(REPLACE ";" "," consumer_policies "${VKRC_POLICIES}")
set(consumer_command ${CMAKE_COMMAND}
  -DVKRC_SOURCE_DIR=${PROJECT_SOURCE_DIR}
  -DVKRC_BINARY_DIR=${PROJECT_BINARY_DIR}
  -DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR}/consumer
  -DPREFIX=${PROJECT_BINARY_DIR}/consumer-prefix
  -DGENERATOR=${CMAKE_GENERATOR}
  -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
  -DBUILD_TYPE=$<CONFIG>
  -DPOLICIES=${consumer_policies})
set(consumer_script ${CMAKE_CURRENT_SOURCE_DIR}/run_consumer.cmake)

if(VKRC_INSTALL)
  add_test(NAME consumer.install COMMAND ${consumer_command} -DSTEP=install -P ${consumer_script})
  add_test(NAME consumer.find_package COMMAND ${consumer_command} -DSTEP=package
    -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/consumer-package -P ${consumer_script})
  set_tests_properties(consumer.install PROPERTIES FIXTURES_SETUP vkrc_installed LABELS consumer)
  set_tests_properties(consumer.find_package PROPERTIES FIXTURES_REQUIRED vkrc_installed
    ENVIRONMENT "${VKRC_TEST_ENV}" LABELS consumer)
  # Installations holding one policy's library (install components).
  foreach(policy IN LISTS VKRC_POLICIES)
    add_test(NAME consumer.find_package_${policy}_only COMMAND ${consumer_command} -DSTEP=one_policy -DONLY_POLICY=${policy}
      -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/consumer-${policy}-only -P ${consumer_script})
    set_tests_properties(consumer.find_package_${policy}_only PROPERTIES FIXTURES_REQUIRED vkrc_installed
      ENVIRONMENT "${VKRC_TEST_ENV}" LABELS consumer)
  endforeach()
endif()
add_test(NAME consumer.add_subdirectory COMMAND ${consumer_command} -DSTEP=subdirectory
  -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/consumer-subdirectory -P ${consumer_script})
# Builds with -j2 inside: ctest -j counts it as two.
set_tests_properties(consumer.add_subdirectory PROPERTIES PROCESSORS 2
  ENVIRONMENT "${VKRC_TEST_ENV}" LABELS consumer)
