# The committed planar model is what scripts/make_gait2d.py derives from the committed
# jw_fullbody.xml: byte for byte (the script is deterministic), so a change to the full-body model
# (its wrap geometry, Hill parameters, joint-limit moments) cannot leave gait2d.xml behind. Under
# a second.
add_test(NAME gait2d_regenerate
  COMMAND bash -c "set -e; out=$(mktemp -d); trap 'rm -rf $out' EXIT; \
    /usr/bin/python3 scripts/make_gait2d.py --out $out/gait2d.xml >/dev/null; \
    cmp $out/gait2d.xml mjmodels/gait2d.xml || \
    { echo 'mjmodels/gait2d.xml differs from scripts/make_gait2d.py output: rerun it'; exit 1; }"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(gait2d_regenerate PROPERTIES LABELS unit TIMEOUT 60)
