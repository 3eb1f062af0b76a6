# docs/FILE_FORMAT.md's promises, on every kind of file through every path
# that writes one (run, merge, a run checkpoint, predict, compare --report,
# atlas and its report, an atlas checkpoint, Python's Result.save), checked
# with h5py alone (tests/cli/file_schema.py).
if(TARGET _fiberlab)
  set(file_schema_python_dir ${FIBERLAB_PYTHON_DIR})
else()
  set(file_schema_python_dir "")
endif()
add_test(NAME file_schema
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/file_schema.sh $<TARGET_FILE:fiberlab>
                 ${PROJECT_SOURCE_DIR} "${file_schema_python_dir}")
set_tests_properties(file_schema PROPERTIES TIMEOUT 120)
