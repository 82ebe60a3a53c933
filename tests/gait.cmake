# Slow end-to-end test of the gait collocation problem (optim/go_gait.h, app/cmd_track.c): the
# tracking solve on jw_fullbody at 20 nodes, at most 200 Ipopt iterations. Passes when the solve
# ran (exit 0 or 3 = stopped short, best iterate written), every output file exists, the summary
# has no NaN, the constraint violation fell at least 100-fold from the initial guess (3.85 ->
# about 5e-3 after 200 iterations with the recalibrated tendon slack lengths, mjmodels/README.md)
# and the defects hold to 1e-6 (scaled). About 70 s on 2 cores.
add_test(NAME gait_track_n20
  COMMAND bash -c "set -e; out=$(mktemp -d); trap 'rm -rf $out' EXIT; \
    $<TARGET_FILE:gaitsim> track ${CMAKE_SOURCE_DIR}/mjmodels/trials/jw_ngait_og5 --out $out \
      --nodes 20 --max-iter 200 --threads 2 || [ $? -eq 3 ]; \
    for f in states.sto controls.sto grf.mot muscle_forces.sto knee_contact.sto summary.json; do test -s $out/$f; done; \
    ! grep -qi nan $out/summary.json; \
    /usr/bin/python3 -c \"import json,sys; s=json.load(open(sys.argv[1])); \
print(s['max_violation'], s['initial_violation']); \
sys.exit(0 if s['max_violation'] * 100 <= s['initial_violation'] and s['max_defect'] <= 1e-6 else 1)\" $out/summary.json")
set_tests_properties(gait_track_n20 PROPERTIES LABELS slow TIMEOUT 900)
