# Exact-by-default and `compare --prediction` with an h5py-written file.
add_test(NAME compare_prediction_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/compare_prediction.sh
                 $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
