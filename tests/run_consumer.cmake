# cmake -DSTEP=install|package|subdirectory -D... -P run_consumer.cmake
# (arguments: see consumer_tests.cmake). Each step fails on the first failed
# command, with its output.
cmake_minimum_required(VERSION 3.25)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " shown "${ARGN}")
    message(FATAL_ERROR "failed (${rc}): ${shown}\n${out}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

# Configures tests/consumer in build_dir with the given cache entries, builds
# it, runs it and checks that it ran under the expected thread policy.
function(build_and_run_consumer build_dir expected_policy)
  run(${CMAKE_COMMAND} --fresh -S ${CONSUMER_SOURCE_DIR} -B ${build_dir} -G ${GENERATOR}
      -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=${BUILD_TYPE} ${ARGN})
  run(${CMAKE_COMMAND} --build ${build_dir} --parallel 2 --config "${BUILD_TYPE}")
  find_program(consumer vkrc_consumer PATHS ${build_dir} ${build_dir}/${BUILD_TYPE} NO_DEFAULT_PATH NO_CACHE REQUIRED)
  run(${consumer})
  message(STATUS "${run_output}")
  if(NOT run_output MATCHES "vkrc consumer \\(policy ${expected_policy}\\): ")
    message(FATAL_ERROR "expected the ${expected_policy} policy, got: ${run_output}")
  endif()
endfunction()

string(REPLACE "," ";" policies "${POLICIES}")

if(STEP STREQUAL "install")
  # Everything into PREFIX; each policy's component alone (with the common
  # one) into PREFIX-<policy>-only.
  file(REMOVE_RECURSE ${PREFIX})
  run(${CMAKE_COMMAND} --install ${VKRC_BINARY_DIR} --prefix ${PREFIX} --config "${BUILD_TYPE}")
  message(STATUS "installed vkrc into ${PREFIX}")
  foreach(policy IN LISTS policies)
    file(REMOVE_RECURSE ${PREFIX}-${policy}-only)
    foreach(component common ${policy})
      run(${CMAKE_COMMAND} --install ${VKRC_BINARY_DIR} --prefix ${PREFIX}-${policy}-only --config "${BUILD_TYPE}"
          --component ${component})
    endforeach()
    message(STATUS "installed vkrc's ${policy} library alone into ${PREFIX}-${policy}-only")
  endforeach()
elseif(STEP STREQUAL "one_policy")
  # An installation holding only ONLY_POLICY's library: find_package succeeds, the
  # user's vkrc::<ONLY_POLICY> works, and vkrc::vkrc exists only when it is that
  # library (mt only with VKRC_THREAD_POLICY=multi).
  if(ONLY_POLICY STREQUAL "st")
    build_and_run_consumer(${WORK_DIR}/st st -DVKRC_CONSUMER_MODE=package -DCMAKE_PREFIX_PATH=${PREFIX}-st-only)
    build_and_run_consumer(${WORK_DIR}/st-named st -DVKRC_CONSUMER_MODE=package -DCMAKE_PREFIX_PATH=${PREFIX}-st-only
                           -DVKRC_CONSUMER_TARGET=vkrc::st -DVKRC_THREAD_POLICY=multi -DVKRC_CONSUMER_EXPECT_NO_DEFAULT=ON)
  else()
    build_and_run_consumer(${WORK_DIR}/mt mt -DVKRC_CONSUMER_MODE=package -DCMAKE_PREFIX_PATH=${PREFIX}-mt-only
                           -DVKRC_CONSUMER_TARGET=vkrc::mt -DVKRC_CONSUMER_EXPECT_NO_DEFAULT=ON)
  endif()
elseif(STEP STREQUAL "package")
  # vkrc::vkrc is vkrc::st by default and vkrc::mt with VKRC_THREAD_POLICY=multi.
  if("st" IN_LIST policies)
    build_and_run_consumer(${WORK_DIR}/st st -DVKRC_CONSUMER_MODE=package -DCMAKE_PREFIX_PATH=${PREFIX})
  endif()
  if("mt" IN_LIST policies)
    build_and_run_consumer(${WORK_DIR}/mt mt -DVKRC_CONSUMER_MODE=package -DCMAKE_PREFIX_PATH=${PREFIX}
                           -DVKRC_THREAD_POLICY=multi)
  endif()
elseif(STEP STREQUAL "subdirectory")
  # One policy's library is enough to show the embedding works.
  list(GET policies 0 policy)
  if(policy STREQUAL "mt")
    set(thread_policy multi)
  else()
    set(thread_policy single)
  endif()
  build_and_run_consumer(${WORK_DIR} ${policy} -DVKRC_CONSUMER_MODE=subdirectory
                         -DVKRC_SOURCE_DIR=${VKRC_SOURCE_DIR} -DVKRC_POLICIES=${policy}
                         -DVKRC_THREAD_POLICY=${thread_policy})
else()
  message(FATAL_ERROR "unknown STEP '${STEP}'")
endif()
