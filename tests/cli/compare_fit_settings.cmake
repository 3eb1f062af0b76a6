# `compare --fit-set`: settings applied only while fitting, judged without them.
add_test(NAME compare_fit_settings_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/compare_fit_settings.sh $<TARGET_FILE:fiberlab>)
set_tests_properties(compare_fit_settings_cli PROPERTIES TIMEOUT 300)
