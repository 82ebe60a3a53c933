#!/usr/bin/env bash
# gaitsim export opened in the real MuJoCo viewer (Debian libmujoco-samples: mujoco-simulate)
# under Xvfb with Mesa's software GL (LIBGL_ALWAYS_SOFTWARE=1): the viewer is paused and reset
# (Space, BackSpace), its menus hidden (Tab, Shift+Tab) with xdotool, and the window grabbed
# with xwd. The body is drawn when the window holds at least 500 coloured pixels (channel
# spread >= 50: the model's orange contact spheres and red muscle paths on a grey floor and sky;
# measured 1884, the empty model 0); the same window on an empty model must hold fewer than 20,
# so a window where nothing is drawn, or whose menus stayed up, fails. The viewer is started up
# to three times when GLFW cannot open its window (seen once in a few runs under load). The keys
# go once the window draws and the grab waits, polling up to 30 s, for the count to fall below a
# quarter of the menus' (measured 191139 with menus, 1459 without): on a loaded machine a fixed
# 3 s once grabbed both windows before they had acted on the keys (450155 pixels each).
# Exit 77 (CTest: skipped), with a SKIPPED line, when Xvfb cannot start on this machine.
# usage: viewer.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"

for tool in Xvfb mujoco-simulate xdotool xwd; do
  if ! command -v "$tool" >/dev/null; then
    echo "FAILED: $tool not installed (scripts/setup.sh installs xvfb, libmujoco-samples, xdotool, x11-apps)" >&2
    exit 1
  fi
done
"$gaitsim" export "$src/tests/fixtures/solution_small" --out k/gait.xml >/dev/null
check "export exits 0" test $? -eq 0
echo '<mujoco model="empty"/>' >empty.xml

# a private X server; the display number comes back on fd 3 once it accepts clients
xvfb_pid="" sim_pid=""
cleanup() {
  [ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null
  cd / && rm -rf "$work"
}
trap cleanup EXIT
Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>display.txt 2>xvfb.log &
xvfb_pid=$!
for _ in $(seq 100); do
  [ -s display.txt ] && break
  kill -0 "$xvfb_pid" 2>/dev/null || break
  sleep 0.1
done
if [ ! -s display.txt ]; then
  echo "SKIPPED: Xvfb cannot start here, so mujoco-simulate was not tried: $(tail -n 2 xvfb.log | tr '\n' ' ')"
  exit 77
fi
export DISPLAY=:$(head -n 1 display.txt) LIBGL_ALWAYS_SOFTWARE=1

# coloured pixels of window WIN now (xwd into NAME.xwd)
grab() {
  xwd -id "$1" -silent >"$2.xwd" || { echo 0; return; }
  /usr/bin/python3 - "$2.xwd" <<'PY'
import sys
import numpy as np
d = open(sys.argv[1], "rb").read()
h = np.frombuffer(d[:100], ">u4")  # XWD header: 25 big-endian words
size, w, hgt, order, bpp, stride, ncolors = h[0], h[4], h[5], h[7], h[11], h[12], h[19]
masks = h[14:17]
assert bpp == 32, "expected 32 bits per pixel"
pix = np.frombuffer(d[size + 12 * ncolors:], "<u4" if order == 0 else ">u4")
pix = pix[: hgt * stride // 4].reshape(hgt, stride // 4)[:, :w]
ch = [(pix & m) >> (int(m) & -int(m)).bit_length() - 1 for m in masks]
spread = np.max(ch, axis=0).astype(int) - np.min(ch, axis=0)
print(int((spread >= 50).sum()))
PY
}

# coloured pixels of mujoco-simulate's window on MODEL, paused at the model's reference pose;
# "none" when no window came up in three tries (GLFW sometimes fails to open on a busy server)
coloured_pixels() {
  local win="" try
  for try in 1 2 3; do
    mujoco-simulate "$1" </dev/null >"$2.$try.log" 2>&1 &
    sim_pid=$!
    for _ in $(seq 300); do
      win=$(xdotool search --name '^Simulate' 2>/dev/null | head -n 1)
      [ -n "$win" ] && break
      kill -0 "$sim_pid" 2>/dev/null || break
      sleep 0.1
    done
    [ -n "$win" ] && break
    echo "try $try: no mujoco-simulate window for $1: $(tail -n 3 "$2.$try.log" | tr '\n' ' ')" >&2
    kill "$sim_pid" 2>/dev/null
    wait "$sim_pid" 2>/dev/null
    sim_pid=""
  done
  if [ -z "$win" ]; then
    echo none
    return
  fi
  # wait until the viewer draws (its menus alone colour many pixels), then pause, reset and hide
  # the menus; under load the window can take seconds to draw and to act on the keys, so poll:
  # the count falls to the scene's once the menus are gone
  local shown=0 now=0
  for _ in $(seq 60); do
    shown=$(grab "$win" "$2")
    [ "$shown" -ge 20000 ] && break
    sleep 0.5
  done
  xdotool key --window "$win" space BackSpace Tab shift+Tab
  for _ in $(seq 60); do
    sleep 0.5
    now=$(grab "$win" "$2")
    [ "$now" -lt $((shown / 4)) ] && break
  done
  echo "$1: $shown coloured pixels before the keys, $now after" >&2
  sleep 1
  grab "$win" "$2"
  kill "$sim_pid" 2>/dev/null
  wait "$sim_pid" 2>/dev/null
  sim_pid=""
}
drawn=$(coloured_pixels k/gait.xml gait)
empty=$(coloured_pixels empty.xml empty)
echo "coloured pixels: export $drawn, empty model $empty"
is_count() { [[ $1 =~ ^[0-9]+$ ]]; }
check "body drawn: $drawn >= 500 coloured pixels" eval 'is_count "$drawn" && test "$drawn" -ge 500'
check "empty model drawn: $empty < 20 coloured pixels" eval 'is_count "$empty" && test "$empty" -lt 20'
finish
