# bench/whole_process.sh runs and reports photons/s per core (case
# a, one run each: about 1.5 s), and refuses a bad flag with exit 2.
add_test(NAME bench_whole_process
         COMMAND bash ${PROJECT_SOURCE_DIR}/bench/whole_process.sh --build ${PROJECT_BINARY_DIR}
                 --runs 1 a)
set_tests_properties(bench_whole_process PROPERTIES TIMEOUT 120
  PASS_REGULAR_EXPRESSION "case a: config \\(4000000 photons\\) [0-9.]+ s, [0-9.]+ M photons/s per core; slope 4 M -> 16 M [0-9.]+ M/s per core")
add_test(NAME bench_whole_process_bad_flag
         COMMAND bash -c "bash \"$0\" --runs 0 2>&1 | grep -q '^usage: bench/whole_process.sh'; test \${PIPESTATUS[0]} -eq 2"
                 ${PROJECT_SOURCE_DIR}/bench/whole_process.sh)
