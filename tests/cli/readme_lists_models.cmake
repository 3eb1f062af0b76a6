# The docs and the help texts name every registered model (their lists come
# from the models' parameter tables).
add_test(NAME readme_lists_models
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/readme_lists_models.sh
                 $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(readme_lists_models PROPERTIES LABELS docs)
