# Slow end-to-end test of the gait collocation problem (optim/go_gait.h, app/cmd_track.c): the
# tracking solve on jw_fullbody at 20 nodes, at most 200 Ipopt iterations. Passes when the solve
# ran (exit 0 or 3 = stopped short, best iterate written), every output file exists, the summary
# has no NaN and the constraint violation fell at least 100-fold from the initial guess.
add_test(NAME gait_track_n20
  COMMAND bash -c "set -e; out=$(mktemp -d); trap 'rm -rf $out' EXIT; \
    $<TARGET_FILE:gaitsim> track ${CMAKE_SOURCE_DIR}/mjmodels/trials/jw_ngait_og5 --out $out \
      --nodes 20 --max-iter 200 --threads 2 || [ $? -eq 3 ]; \
    for f in states.sto controls.sto grf.mot muscle_forces.sto summary.json; do test -s $out/$f; done; \
    ! grep -qi nan $out/summary.json; \
    /usr/bin/python3 -c \"import json,sys; s=json.load(open(sys.argv[1])); \
print(s['max_violation'], s['initial_violation']); \
sys.exit(0 if s['max_violation'] * 100 <= s['initial_violation'] else 1)\" $out/summary.json")
set_tests_properties(gait_track_n20 PROPERTIES LABELS slow TIMEOUT 900)
# Held back: with JW's right-leg tendon slack lengths as in the .osim (mjmodels/README.md, "right
# leg muscle lengths"), rectus femoris and the vasti sit at 2-2.7 optimal fibre lengths at the
# trial poses, so the Hill rows cannot be met and the solve cannot become feasible. Enable when
# the muscle parameters are recalibrated (issue #6).
set_tests_properties(gait_track_n20 PROPERTIES DISABLED TRUE)
