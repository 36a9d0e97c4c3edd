#!/usr/bin/env bash
# End-to-end checks of the stylus-tool binary: exit codes, messages and outputs.
# Usage: cli_test.sh STYLUS_TOOL SOURCE_DIR WORK_DIR
set -u
tool=$1 src=$2 work=$3
mkdir -p "$work"
passed=0 failed=0

# check NAME EXPECTED_EXIT REGEX -- COMMAND...: runs COMMAND, checks its exit
# code and that stdout+stderr match REGEX (extended grep).
check() {
  local name=$1 want=$2 regex=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -eq "$want" ] && grep -Eq -- "$regex" <<<"$out"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: exit $rc (want $want), output:"
    echo "$out" | head -20
  fi
}

good=$src/tests/fixtures/bvh/good/mixed_orders_crlf.bvh
bad=$src/tests/fixtures/bvh/bad
check "help" 0 "bvh-roundtrip" -- "$tool" --help
check "no command" 2 "usage" -- "$tool"
check "unknown command" 2 "unknown command 'frobnicate'" -- "$tool" frobnicate
for cmd in bvh-info bvh-roundtrip features dataset-stats synth render; do
  check "$cmd --help" 0 "usage: stylus-tool $cmd" -- "$tool" "$cmd" --help
done
check "unknown option" 2 "unknown option --bogus" -- "$tool" bvh-info --bogus "$good"
check "bvh-info" 0 "joints: 3 .*" -- "$tool" bvh-info "$good"
check "bvh-info orders" 0 "order YZX" -- "$tool" bvh-info "$good"
check "bvh-info bad file" 1 "nan_value.bvh:25: .*'nan' is not a finite number" -- "$tool" bvh-info "$bad/nan_value.bvh"
check "bvh-info missing file" 1 "cannot open file" -- "$tool" bvh-info "$work/none.bvh"
check "roundtrip" 0 "^max_fk_error=0$" -- "$tool" bvh-roundtrip "$good" "$work/rt.bvh"
check "roundtrip unwritable" 1 "cannot open for writing" -- "$tool" bvh-roundtrip "$good" /nonexistent-dir/out.bvh
check "synth" 0 "wrote .*: 45 frames" -- "$tool" synth --style old,frames=45 -o "$work/old.bvh"
check "synth bad knob" 1 "unknown style knob 'wings'" -- "$tool" synth --style wings=3 -o "$work/x.bvh"
check "synth needs -o" 2 "-o FILE is required" -- "$tool" synth --style old
check "features" 0 "max_reconstruction_error=([0-9.]+e-0[4-9]|0(\.00[0-9]*)?)$" -- "$tool" features "$work/old.bvh" -o "$work/rebuilt.bvh"
check "features rebuilt parses" 0 "frames: 45" -- "$tool" bvh-info "$work/rebuilt.bvh"
check "features non-humanoid" 1 "not a recognizable humanoid" -- "$tool" features "$good"
check "render" 0 "wrote .*walk.svg" -- "$tool" render "$work/old.bvh" -o "$work/walk.svg"
check "render svg" 0 "<svg" -- cat "$work/walk.svg"
check "dataset-stats missing dir" 1 "not a directory" -- "$tool" dataset-stats "$work/none"
for s in walk_normal walk_old run; do
  check "sample $s" 0 "joints: 22" -- "$tool" bvh-info "$src/samples/$s.bvh"
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
