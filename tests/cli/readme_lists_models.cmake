# Issue 7: README's model tables come from the models' parameter tables.
add_test(NAME readme_lists_models
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/readme_lists_models.sh
                 $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
