# MPI ranks, SIGINT/SIGTERM + resume, split-sweep merge and the
# target-error stop, each compared bit for bit with one uninterrupted process.
foreach(case mpi signal merge target)
  add_test(NAME scale_out_${case}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/cli/scale_out_test.py
                   $<TARGET_FILE:fiberlab> ${case})
  set_tests_properties(scale_out_${case} PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)
endforeach()
# The MPI case runs up to 3 processes at once.
set_tests_properties(scale_out_mpi PROPERTIES PROCESSORS 2)
