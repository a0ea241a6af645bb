# Installs the client package into STAGE, checks what was installed, then
# configures, builds and runs the consumer project against it.
#   cmake -DBUILD_DIR=... -DSTAGE=... -DCONSUMER_SOURCE=... -DCONSUMER_BUILD=...
#         -DGENERATOR=... -P run_consumer.cmake
foreach(var BUILD_DIR STAGE CONSUMER_SOURCE CONSUMER_BUILD GENERATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer.cmake needs -D${var}=...")
  endif()
endforeach()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${what} failed (${result}):\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${STAGE} ${CONSUMER_BUILD})
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${STAGE} --component client)

# What a user gets: the headers, the library, the package, dh3ctl.
foreach(path include/dh3/client.hpp include/dh3/types.hpp include/dh3/address.hpp
             include/dh3/registers.hpp include/dh3/export.hpp
             lib/cmake/dh3client/dh3clientConfig.cmake
             lib/cmake/dh3client/dh3clientConfigVersion.cmake
             lib/cmake/dh3client/dh3clientTargets.cmake bin/dh3ctl bin/pick_loop
             bin/event_watcher)
  if(NOT EXISTS ${STAGE}/${path})
    message(FATAL_ERROR "not installed: ${path}")
  endif()
endforeach()
file(GLOB libraries ${STAGE}/lib/libdh3client.so*)
if(NOT libraries)
  message(FATAL_ERROR "libdh3client.so was not installed in ${STAGE}/lib")
endif()

# The public headers must not drag in the middleware or the generated types.
file(GLOB_RECURSE headers ${STAGE}/include/*)
foreach(header ${headers})
  file(STRINGS ${header} includes REGEX "^[ \t]*#[ \t]*include")
  foreach(line ${includes})
    if(line MATCHES "fastdds|fastrtps|fastcdr|dh3_contract|dh3/contract/")
      message(FATAL_ERROR "${header} includes middleware or generated code: ${line}")
    endif()
    if(line MATCHES "\"" AND NOT line MATCHES "\"dh3/")
      message(FATAL_ERROR "${header} includes a header that is not installed: ${line}")
    endif()
  endforeach()
endforeach()

run("configuring the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${CONSUMER_BUILD}
    -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${STAGE})
run("building the consumer" ${CMAKE_COMMAND} --build ${CONSUMER_BUILD})

# A domain of its own, so that no service of another test answers.
string(RANDOM LENGTH 2 ALPHABET 0123456789 domain)
math(EXPR domain "200 + ${domain} % 30")
run("running the consumer" ${CONSUMER_BUILD}/consumer ${domain})
if(NOT last_output MATCHES "no service found")
  message(FATAL_ERROR "unexpected consumer output:\n${last_output}")
endif()
message(STATUS "consumer: ${last_output}")

# The installed dh3ctl runs from the staging prefix (its RPATH finds the library).
run("installed dh3ctl --help" ${STAGE}/bin/dh3ctl --help)
if(NOT last_output MATCHES "set-can-id")
  message(FATAL_ERROR "installed dh3ctl --help printed:\n${last_output}")
endif()

# So do the examples (installed as programs too).
foreach(example pick_loop event_watcher)
  run("installed ${example} --help" ${STAGE}/bin/${example} --help)
  if(NOT last_output MATCHES "--security-dir")
    message(FATAL_ERROR "installed ${example} --help printed:\n${last_output}")
  endif()
endforeach()
