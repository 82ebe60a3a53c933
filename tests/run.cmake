# Slow test of gaitsim run: each solve step in a process of its own, so that its predictions are
# bitwise those of gaitsim sweep from the same tracking solution (tests/slow/run_one_process.sh).
# About 2.5 min on 2 cores.
add_test(NAME run_one_process
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slow/run_one_process.sh $<TARGET_FILE:gaitsim>
          ${CMAKE_SOURCE_DIR})
set_tests_properties(run_one_process PROPERTIES LABELS slow TIMEOUT 900)
