# `fiberlab atlas` on a tiny sweep (seconds): table, report,
# a recovered parameter, one-line config errors, Ctrl-C.
add_test(NAME atlas_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_cli PROPERTIES TIMEOUT 300)
# `fiberlab atlas` with model variants (configs/atlas_variants.yaml): named
# in file, report and info; a variant without parameters equals its model;
# one-line errors for bad entries.
add_test(NAME atlas_variants_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_variants.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_variants_cli PROPERTIES TIMEOUT 300)
# huang2022's `form: cycles_eval` (Cycles' eval()) as an atlas variant beside
# the paper's form: named in file, report and info; only TT and TRT move.
add_test(NAME atlas_huang_cycles_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_huang_cycles.sh $<TARGET_FILE:fiberlab>)
set_tests_properties(atlas_huang_cycles_cli PROPERTIES TIMEOUT 300)
# fit.model_parameters: huang2022 fitted at a cheap quadrature, judged at
# another; after-fit chi-square equal to a separate compare of the fitted
# values at the judged one; bad settings refused in one line.
add_test(NAME atlas_fit_settings_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_fit_settings.sh $<TARGET_FILE:fiberlab>)
set_tests_properties(atlas_fit_settings_cli PROPERTIES TIMEOUT 300)
# `mpirun -np 2 fiberlab atlas` (and its --resume of a one-process
# checkpoint) bit-identical to one process; skipped without mpirun.
add_test(NAME atlas_mpi_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_mpi.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_mpi_cli PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600)
# `fiberlab atlas` with fit.per_lobe: each lobe's chi-square after its own
# fit at most the joint fit's (the oracle), resume and mpirun -np 2 equal to
# one process, bad per_lobe values refused in one line.
add_test(NAME atlas_per_lobe_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_per_lobe.sh $<TARGET_FILE:fiberlab> ${PROJECT_SOURCE_DIR})
set_tests_properties(atlas_per_lobe_cli PROPERTIES TIMEOUT 600)
# `fiberlab atlas` sweeping fibers with and without a medulla (two channels,
# both orders): the lobe `scattered` in the file's lobe axis, NaN where a fiber
# has none.
add_test(NAME atlas_medulla_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/atlas_medulla.sh $<TARGET_FILE:fiberlab>)
set_tests_properties(atlas_medulla_cli PROPERTIES TIMEOUT 300)
