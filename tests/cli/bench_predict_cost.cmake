# bench/predict_cost.py runs (one repeat, one bench config: about 1 s) and
# prints its row with both times and the ratios; --repeats 0 is refused.
add_test(NAME bench_predict_cost
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/bench/predict_cost.py --fiberlab $<TARGET_FILE:fiberlab>
                 --repeats 1 bench/configs/predict_white_ggx_18x36.yaml)
set_tests_properties(bench_predict_cost PROPERTIES TIMEOUT 120
  PASS_REGULAR_EXPRESSION "bench/configs/predict_white_ggx_18x36.yaml +[0-9.]+ \\([0-9.]+\\) +[0-9.]+ \\([0-9.]+\\) +[0-9]+ / [0-9]+")
add_test(NAME bench_predict_cost_bad_flag
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/bench/predict_cost.py --repeats 0)
set_tests_properties(bench_predict_cost_bad_flag PROPERTIES WILL_FAIL TRUE)
