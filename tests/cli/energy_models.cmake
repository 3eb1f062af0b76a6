# `fiberlab energy` evaluates every registered model unless --models says
# otherwise; on an elliptical fiber the circular-only models are listed as
# not applicable, not dropped silently.
add_test(NAME energy_default_models
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/energy_models.sh $<TARGET_FILE:fiberlab>)
set_tests_properties(energy_default_models PROPERTIES TIMEOUT 120)
