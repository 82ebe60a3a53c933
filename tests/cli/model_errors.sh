#!/usr/bin/env bash
# gaitsim --version/--help work; a broken or missing model gives one line
# "gaitsim: MODEL: reason" on stderr, exit status 1, no prompt on stdin, no MUJOCO_LOG.TXT.
# usage: model_errors.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1
source "$(dirname "$0")/../cli_common.bash"

out=$("$gaitsim" --version)
check "version names gaitsim" grep -q '^gaitsim [0-9]' <<<"$out"
check "version names MuJoCo 2.2" grep -q '^MuJoCo 2\.2' <<<"$out"
check "version names Ipopt 3.11" grep -q '^Ipopt 3\.11' <<<"$out"
check "help lists info" grep -q 'info' <<<"$("$gaitsim" --help)"
"$gaitsim" no-such-command 2>/dev/null; check "unknown command exits 2" test $? -eq 2

# a model that compiles is summarised
cat > ok.xml <<'XML'
<mujoco><worldbody><body><joint name="hinge1" type="hinge"/><geom size=".1" mass="2"/></body></worldbody></mujoco>
XML
out=$("$gaitsim" info ok.xml --json)
check "json dof" grep -q '"dof":[[:space:]]*1' <<<"$out"
check "json mass" grep -q '"mass_kg":[[:space:]]*2' <<<"$out"

# broken models: each exits 1 with one line naming the file, without waiting on stdin
printf '<mujoco><worldbody><geom type="sphere"/></worldbody></mujoco>' > zero_size.xml
printf '<mujoco><worldbody' > truncated.xml
printf '<mujoco><worldbody><body><joint axis="0 0 0"/><geom size=".1"/></body></worldbody></mujoco>' > zero_axis.xml
printf 'not xml at all' > garbage.xml
# stdin: a FIFO held open for reading and writing, so a prompt would block until timeout
mkfifo stdin.fifo
exec 3<>stdin.fifo
for model in zero_size.xml truncated.xml zero_axis.xml garbage.xml missing.xml; do
  err=$(timeout 10 "$gaitsim" info "$model" 2>&1 >/dev/null <&3)
  status=$?
  check "$model exits 1 (got $status)" test "$status" -eq 1
  check "$model one line" test "$(printf '%s\n' "$err" | wc -l)" -eq 1
  check "$model names file" grep -q "^gaitsim: $model: ." <<<"$err"
done
check "no MUJOCO_LOG.TXT" test ! -e MUJOCO_LOG.TXT

finish
