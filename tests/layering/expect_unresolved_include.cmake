# cmake -DBUILD_DIR=... -DCASE=target -DCONTROL=target -DHEADER=dh3/x/y.hpp -P this
# Passes only if CONTROL builds and CASE fails because HEADER does not resolve.
foreach(var BUILD_DIR CASE CONTROL HEADER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "expect_unresolved_include.cmake: ${var} is not set")
  endif()
endforeach()

execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${CONTROL}
  RESULT_VARIABLE control_result OUTPUT_VARIABLE control_output ERROR_VARIABLE control_output)
if(NOT control_result EQUAL 0)
  message(FATAL_ERROR "${CONTROL}, with the higher layer linked, does not build either, "
    "so ${CASE} would prove nothing:\n${control_output}")
endif()

execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${CASE}
  RESULT_VARIABLE case_result OUTPUT_VARIABLE case_output ERROR_VARIABLE case_output)
if(case_result EQUAL 0)
  message(FATAL_ERROR "${CASE} builds: the lower layer reaches ${HEADER}")
endif()
string(FIND "${case_output}" "${HEADER}: No such file or directory" unresolved)
if(unresolved EQUAL -1)
  message(FATAL_ERROR "${CASE} fails, but not because ${HEADER} does not resolve:\n${case_output}")
endif()
message(STATUS "${CASE}: ${HEADER} does not resolve, as the layering wants")
