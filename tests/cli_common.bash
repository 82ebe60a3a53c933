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

# PNG checks of the report tests
png_info() {  # "ok WxH" for a file with the PNG signature and an IHDR chunk, else "bad"
  python3 -c '
import struct, sys
d = open(sys.argv[1], "rb").read(24)
ok = d[:8] == b"\x89PNG\r\n\x1a\n" and d[12:16] == b"IHDR"
print("ok %dx%d" % struct.unpack(">II", d[16:24]) if ok else "bad")' "$1" 2>/dev/null || echo bad
}
plausible_png() {  # plausible_png FILE: valid PNG, 400..4000 px each way, over 10 kB
  local info w h
  info=$(png_info "$1")
  [[ $info == ok\ * ]] || return 1
  w=${info#ok } h=${w#*x} w=${w%x*}
  test "$w" -ge 400 -a "$w" -le 4000 -a "$h" -ge 300 -a "$h" -le 4000 -a "$(stat -c %s "$1")" -gt 10000
}
