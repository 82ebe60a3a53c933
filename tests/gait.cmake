# Slow end-to-end test of the gait collocation problem (optim/go_gait.h, app/cmd_solve.c): the
# tracking solve on the default model (jw_fullbody_knee6) at 20 nodes, at most 200 Ipopt iterations. Passes when the solve
# ran (exit 0 or 3 = stopped short, best iterate written; --refine 0: no exact-Hessian stage, which
# tests/cli/refine.sh covers), every output file exists, the summary
# has no NaN, the feasibility polish took the best iterate (violation ~1e-3 after 200 L-BFGS
# iterations from about 4, with the recalibrated tendon slack lengths of mjmodels/README.md) to a
# dynamically consistent point: every scaled constraint within 1e-8, defects within 1e-6.
# About 70 s on 2 cores.
add_test(NAME gait_track_n20
  COMMAND bash -c "set -e; out=$(mktemp -d); trap 'rm -rf $out' EXIT; \
    $<TARGET_FILE:gaitsim> track ${CMAKE_SOURCE_DIR}/mjmodels/trials/jw_ngait_og5 --out $out \
      --nodes 20 --max-iter 200 --threads 2 --refine 0 || [ $? -eq 3 ]; \
    for f in states.sto controls.sto grf.mot muscle_forces.sto knee_contact.sto summary.json; do test -s $out/$f; done; \
    ! grep -qi nan $out/summary.json; \
    /usr/bin/python3 -c \"import json,sys; s=json.load(open(sys.argv[1])); \
print(s['max_violation'], s['initial_violation']); \
sys.exit(0 if s['max_violation'] <= 1e-8 and s['polish']['used'] and s['max_defect'] <= 1e-6 else 1)\" $out/summary.json")
set_tests_properties(gait_track_n20 PROPERTIES LABELS slow TIMEOUT 900)
