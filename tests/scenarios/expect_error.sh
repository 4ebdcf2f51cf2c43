#!/bin/sh
# expect_error.sh STATUS REGEX COMMAND [ARGS...]
# Passes when COMMAND exits with STATUS and its standard error matches REGEX (grep -E).
# CTest's PASS_REGULAR_EXPRESSION ignores the exit status, hence this wrapper.
status=$1
regex=$2
shift 2
err=$("$@" 2>&1 >/dev/null)
rc=$?
printf '%s\n' "$err"
if [ "$rc" -ne "$status" ]; then
  echo "expect_error: exit status $rc, expected $status" >&2
  exit 1
fi
if ! printf '%s\n' "$err" | grep -Eq -- "$regex"; then
  echo "expect_error: stderr does not match: $regex" >&2
  exit 1
fi
exit 0
