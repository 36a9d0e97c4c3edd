# Shared by the CLI test scripts: `check NAME EXPECTED_EXIT REGEX -- COMMAND...`
# runs COMMAND, checks its exit code and that stdout+stderr match REGEX
# (extended grep), and counts into $passed / $failed.
passed=0 failed=0
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
