# Shared by the CLI tests in tests/cli/ (sourced, not run): counters, `check NAME CONDITION...`,
# a temporary working folder removed on exit (the script runs inside it), and `finish`, which
# prints "N passed, N failed" and returns non-zero when anything failed.
fail=0 pass=0
check() {  # check NAME CONDITION...: run CONDITION, count it, name it when it fails
  local name=$1; shift
  if "$@"; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAILED: $name" >&2; fi
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
finish() {
  echo "$pass passed, $fail failed"
  test "$fail" -eq 0
}
