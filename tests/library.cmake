# libgaitsim installed into a temporary prefix and used by examples/forward_gait.c through
# pkg-config (tests/library/example.sh); needs the shared library built.
add_test(NAME cli_library_example
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/library/example.sh $<TARGET_FILE:gaitsim>
          ${CMAKE_BINARY_DIR} ${CMAKE_SOURCE_DIR})
set_tests_properties(cli_library_example PROPERTIES LABELS cli TIMEOUT 120)
