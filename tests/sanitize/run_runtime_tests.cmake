# Configures and builds the runtime's tests under ASan and UBSan (QUIVER_SANITIZE), makes their
# model and runs them (cmake -P script, run by ctest as sanitize.runtime).
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${BINARY} -G Ninja
  -DCMAKE_C_COMPILER=${CC} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=RelWithDebInfo -DQUIVER_SANITIZE=ON
  -DQUIVER_BUILD_BAKE=OFF -DQUIVER_BUILD_VIEWER=OFF -DQUIVER_BUILD_BENCH=OFF -DQUIVER_BUILD_EXAMPLES=OFF
  -DQUIVER_BUILD_PYTHON=OFF -DQUIVER_INSTALL=OFF
  RESULT_VARIABLE configured)
if(NOT configured EQUAL 0)
  message(FATAL_ERROR "configuring the sanitizer tree failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BINARY} --target quiver_runtime_tests quiver_test_model
  RESULT_VARIABLE built)
if(NOT built EQUAL 0)
  message(FATAL_ERROR "building the sanitizer tree failed")
endif()
set(model_dir ${BINARY}/tests/test_model)  # where the tree's tests look for it (QUIVER_RUNTIME_MODEL)
file(MAKE_DIRECTORY ${model_dir})
execute_process(COMMAND ${BINARY}/tests/quiver_test_model ${model_dir}/beam.qvr ${model_dir}/free_beam.qvr
  RESULT_VARIABLE made)
if(NOT made EQUAL 0)
  message(FATAL_ERROR "making the test model under the sanitizers failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
  ${BINARY}/tests/quiver_runtime_tests RESULT_VARIABLE passed)
if(NOT passed EQUAL 0)
  message(FATAL_ERROR "the runtime's tests failed under ASan and UBSan")
endif()
