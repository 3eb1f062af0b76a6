# Every output and table the docs show is what the program prints now:
# scripts/doc_outputs.py re-runs each quick generator (the quickstart, the
# model tables, `fiberlab --help`, the smooth circle's comparison, the small
# atlas) and diffs it against the docs' marked blocks. A stale number fails
# here; `scripts/doc_outputs.py --write` regenerates them.
add_test(NAME docs_outputs
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/scripts/doc_outputs.py --check
                 --fiberlab $<TARGET_FILE:fiberlab>)
set_tests_properties(docs_outputs PROPERTIES LABELS docs TIMEOUT 300)
