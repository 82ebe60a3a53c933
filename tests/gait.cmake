# Slow end-to-end test of the gait collocation problem: the tracking solve on the default model
# at 20 nodes, 200 Ipopt iterations, and the figures it must reach (tests/slow/gait_track_n20.sh
# says which and why). About 70 s on 2 cores.
add_test(NAME gait_track_n20
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/slow/gait_track_n20.sh $<TARGET_FILE:gaitsim>
          ${CMAKE_SOURCE_DIR})
set_tests_properties(gait_track_n20 PROPERTIES LABELS slow TIMEOUT 900)
