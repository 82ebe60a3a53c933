# Stock MuJoCo's own benchmark program runs the stock model (mjmodels/jw_fullbody_mujoco.xml,
# scripts/make_stock_model.py): mujoco-testspeed (Debian libmujoco-samples, installed by
# scripts/setup.sh) loads it and steps it 500 times with control noise 0.01; it must report a time
# per step and no MuJoCo error. The time per step is in docs/BENCHMARKS.md. Under a second.
find_program(GS_MUJOCO_TESTSPEED mujoco-testspeed)
if(GS_MUJOCO_TESTSPEED)
  add_test(NAME stock_model_testspeed
    COMMAND ${GS_MUJOCO_TESTSPEED} ${CMAKE_SOURCE_DIR}/mjmodels/jw_fullbody_mujoco.xml 500 1 0.01)
  set_tests_properties(stock_model_testspeed PROPERTIES LABELS unit TIMEOUT 60
    PASS_REGULAR_EXPRESSION "Time per step *: [0-9.]+ ms"
    FAIL_REGULAR_EXPRESSION "[Ee]rror|[Ww]arning")
endif()

# The committed stock model is what scripts/make_stock_model.py writes from the committed sources
# with the built gaitsim: every element and attribute equal, and each muscle fitting gaitsim's
# forces within 0.005 Fmax RMS of a fresh fit (--check; the non-convex muscle fits move with the
# machine's floating point, so no byte-for-byte comparison). About 80 s of CPU, 95 s measured on
# the shared 2 cores (142 poses x 3 activations of `gaitsim inspect`, then the fits).
add_test(NAME stock_model_regenerate
  COMMAND /usr/bin/python3 scripts/make_stock_model.py --gaitsim $<TARGET_FILE:gaitsim>
    --check mjmodels/jw_fullbody_mujoco.xml
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(stock_model_regenerate PROPERTIES LABELS slow TIMEOUT 600)
