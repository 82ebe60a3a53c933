# the catalogue of bad input and faults (tests/cli/bad_inputs.sh) runs about 50 planar-model
# commands and four signalled solves: about a minute, more under the sanitizers
set_tests_properties(cli_bad_inputs PROPERTIES TIMEOUT 300)
