# Configures and builds the clang + libFuzzer + sanitizer tree (cmake -P script, run by ctest).
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${BINARY} -G Ninja
  -DCMAKE_C_COMPILER=${CC} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=RelWithDebInfo
  -DQUIVER_BUILD_FUZZERS=ON -DQUIVER_BUILD_TESTS=OFF -DQUIVER_BUILD_TOOLS=OFF -DQUIVER_BUILD_BAKE=OFF
  -DQUIVER_BUILD_BENCH=OFF
  RESULT_VARIABLE configured)
if(NOT configured EQUAL 0)
  message(FATAL_ERROR "configuring the fuzz tree failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BINARY} RESULT_VARIABLE built)
if(NOT built EQUAL 0)
  message(FATAL_ERROR "building the fuzz tree failed")
endif()
