# `fiberlab atlas` checkpoints and --resume: SIGINT, SIGKILL
# and SIGTERM, refusals, damaged checkpoints, and resumed results
# bit-identical to an uninterrupted run (tests/cli/atlas_same_results.py).
add_test(NAME atlas_resume_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_resume.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_resume_cli PROPERTIES TIMEOUT 300)
# The resume of a sweep with a medullated fiber (one lobe more than the
# tally's, `scattered`) and fit.per_lobe, in both sweep orders, and the
# same sweep on two ranks (when mpirun is installed).
add_test(NAME atlas_medulla_resume_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_medulla_resume.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_medulla_resume_cli PROPERTIES TIMEOUT 300)
