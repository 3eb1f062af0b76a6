# Debian's /usr/bin/python3 with h5py reads every SPEC s9 name.
add_test(NAME python_reads_result
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/python_reads_result.sh
                 $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
