#!/usr/bin/env bash
# gaitsim render on the fixture solution (tests/fixtures/solution_small): the mp4 decodes
# (ffprobe) with the right size and fps x duration frames; --png, --strip and --frames write
# what they say; without ffmpeg, PNG frames and a message; a bare model with --pose; a solution
# folder with a missing or malformed file exits 1 with one line naming the file and leaves no
# video, not even a temporary one; usage errors exit 2; no EGL or GLX linked.
# usage: render.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
fixture=$src/tests/fixtures/solution_small
source "$(dirname "$0")/../cli_common.bash"

png_size() {  # width x height of a PNG, from its IHDR chunk
  python3 -c 'import struct,sys; d=open(sys.argv[1],"rb").read(24); print("%dx%d" % struct.unpack(">II", d[16:24]))' "$1"
}
# frames expected: round(fps x cycles x stride time), the stride from states.sto's time column
stride=$(awk 'f && NF {t=$1} /^endheader/ {f=1; getline} END {print t}' "$fixture/states.sto")
expect_frames() { python3 -c "import sys; print(round($1 * $2 * $stride))"; }

# video: size, frame count, decodes
if command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null; then
  out=$("$gaitsim" render "$fixture" --out gait.mp4 --size 320x240 --fps 20 --cycles 2)
  check "mp4 exits 0" test $? -eq 0
  check "mp4 written" test -s gait.mp4
  probe=$(ffprobe -v error -count_frames -select_streams v:0 \
    -show_entries stream=codec_name,width,height,nb_read_frames -of csv=p=0 gait.mp4)
  want=$(expect_frames 20 2)
  check "mp4 is h264 320x240 with $want frames (got $probe)" test "$probe" = "h264,320,240,$want"
  check "command reports $want frames" grep -q "$want frames" <<<"$out"
  check "no temporary files left" test -z "$(ls -A | grep -v '^gait.mp4$')"
else
  echo "ffmpeg/ffprobe not installed: mp4 checks skipped (scripts/setup.sh installs ffmpeg)"
fi

# one frame, a filmstrip, numbered frames
"$gaitsim" render "$fixture" --png one.png --at 0.35 --size 160x120 >/dev/null
check "png exits 0" test $? -eq 0
check "png is 160x120" test "$(png_size one.png)" = 160x120
"$gaitsim" render "$fixture" --strip strip.png --count 4 --size 80x120 >/dev/null
check "strip exits 0" test $? -eq 0
check "strip is 4 x 80 wide" test "$(png_size strip.png)" = 320x120
"$gaitsim" render "$fixture" --frames frames --size 64x48 --fps 10 >/dev/null
check "frames exits 0" test $? -eq 0
want=$(expect_frames 10 1)
check "frames: $want PNGs" test "$(ls frames | grep -c '^frame_[0-9]*\.png$')" -eq "$want"

# no ffmpeg on PATH: PNG frames instead, with a message, exit 0
mkdir -p emptybin
err=$(PATH=$PWD/emptybin "$gaitsim" render "$fixture" --out noff.mp4 --size 64x48 --fps 5 2>&1 >/dev/null)
check "no ffmpeg exits 0" test $? -eq 0
check "no ffmpeg says so" grep -q "ffmpeg not found" <<<"$err"
check "no ffmpeg: no mp4" test ! -e noff.mp4
check "no ffmpeg: frames in noff_frames/" test "$(ls noff_frames | grep -c '\.png$')" -eq "$(expect_frames 5 1)"

# a bare model with a pose file (the trial's coordinates)
"$gaitsim" render "$src/mjmodels/jw_fullbody.xml" --pose "$src/mjmodels/trials/jw_ngait_og5/coordinates.mot" \
  --png pose.png --at 0.5 --size 64x48 >/dev/null
check "bare model exits 0" test $? -eq 0
check "bare model png" test "$(png_size pose.png)" = 64x48

# missing or malformed files: exit 1, one line naming the file, no video and no temporary file
mkdir -p bad out
for case in missing_states missing_grf missing_controls nan_states bad_grf; do
  rm -rf bad/* out/*
  cp "$fixture"/*.sto "$fixture"/*.mot bad/
  case $case in
    missing_states) rm bad/states.sto; name=states.sto ;;
    missing_grf) rm bad/grf.mot; name=grf.mot ;;
    missing_controls) rm bad/controls.sto; name=controls.sto ;;
    nan_states) sed -i '0,/^0\t/s/^0\t[^\t]*/0\tnan/' bad/states.sto; name=states.sto ;;
    bad_grf) head -n 12 bad/grf.mot | sed 's/^0\t.*/0\t1\t2/' > bad/g && mv bad/g bad/grf.mot; name=grf.mot ;;
  esac
  err=$("$gaitsim" render bad --out out/gait.mp4 --size 64x48 --fps 5 2>&1 >/dev/null)
  status=$?
  check "$case exits 1 (got $status)" test "$status" -eq 1
  check "$case one line naming $name: $err" grep -q "^gaitsim: .*$name" <<<"$err"
  check "$case one line" test "$(printf '%s\n' "$err" | wc -l)" -eq 1
  check "$case leaves no video or temporary file" test -z "$(ls -A out)"
done

# usage errors
"$gaitsim" render "$fixture" 2>/dev/null
check "no output is a usage error" test $? -eq 2
"$gaitsim" render "$fixture" --png a.png --strip b.png 2>/dev/null
check "two outputs is a usage error" test $? -eq 2
"$gaitsim" render "$fixture" --png a.png --size 12x1 2>/dev/null
check "bad size is a usage error" test $? -eq 2
"$gaitsim" render "$fixture" --out a.mp4 --size 161x120 2>/dev/null
check "odd video size is a usage error" test $? -eq 2
"$gaitsim" render "$fixture" --png a.png --camera top 2>/dev/null
check "unknown camera is a usage error" test $? -eq 2
"$gaitsim" render "$src/mjmodels/jw_fullbody.xml" --png a.png 2>/dev/null
check "a model without --pose is a usage error" test $? -eq 2

# headless: nothing linked with EGL or GLX
check "no EGL/GLX linked" test -z "$(ldd "$gaitsim" | grep -i -E 'egl|glx')"

finish
