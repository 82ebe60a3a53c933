# gaitsim export (issue 21, item 2): keyframes checked in stock MuJoCo (tests/export/export.sh,
# with test_keyframes as the checker), and the export opened in the real mujoco-simulate under
# Xvfb (tests/export/viewer.sh; exit 77, reported by CTest as skipped, when Xvfb cannot start).
add_test(NAME cli_export
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/export/export.sh $<TARGET_FILE:gaitsim>
          $<TARGET_FILE:test_keyframes> ${CMAKE_SOURCE_DIR})
set_tests_properties(cli_export PROPERTIES LABELS cli TIMEOUT 120)
add_test(NAME cli_export_viewer
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/export/viewer.sh $<TARGET_FILE:gaitsim> ${CMAKE_SOURCE_DIR})
set_tests_properties(cli_export_viewer PROPERTIES LABELS cli TIMEOUT 240 SKIP_RETURN_CODE 77)
