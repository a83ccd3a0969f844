# deken.cmake -- packs the Pd library as a deken package (run by the `deken`
# target, cmake/pd_library.cmake): installs the component pd_library of
# BUILD_DIR into STAGE_DIR (the same files and RUNPATHs as `cmake --install`),
# puts ICTUSD (if given) into the folder, and zips STAGE_DIR/.../ictus/ as
# DEK_FILE, with DEK_FILE.sha256 beside it.
#   cmake -DBUILD_DIR=... -DSTAGE_DIR=... -DDEK_FILE=... [-DICTUSD=...] -P deken.cmake
foreach(var BUILD_DIR STAGE_DIR DEK_FILE)
  if(NOT ${var})
    message(FATAL_ERROR "deken.cmake: -D${var}=... is required")
  endif()
endforeach()

file(REMOVE_RECURSE ${STAGE_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${STAGE_DIR}
                        --component pd_library
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "deken.cmake: cmake --install of the pd_library component failed (${rc})")
endif()
set(library_parent ${STAGE_DIR}/lib/pd-externals)
if(ICTUSD)
  file(COPY ${ICTUSD} DESTINATION ${library_parent}/ictus
       FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                        WORLD_READ WORLD_EXECUTE)
endif()

file(REMOVE ${DEK_FILE} ${DEK_FILE}.sha256)
# A .dek is a zip whose top level is the library's folder.
execute_process(COMMAND ${CMAKE_COMMAND} -E tar cf ${DEK_FILE} --format=zip ictus
                WORKING_DIRECTORY ${library_parent}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT EXISTS ${DEK_FILE})
  message(FATAL_ERROR "deken.cmake: zipping ${library_parent}/ictus failed (${rc})")
endif()
file(SHA256 ${DEK_FILE} sha)
get_filename_component(dek_name ${DEK_FILE} NAME)
file(WRITE ${DEK_FILE}.sha256 "${sha}  ${dek_name}\n")
message(STATUS "deken package: ${DEK_FILE}")
