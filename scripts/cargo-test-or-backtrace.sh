#!/bin/sh
# Runs `cargo test` with the given arguments. Where a test binary dies of a signal (a driver crash, which no Rust
# panic message explains), runs that binary once more under gdb, where there is one, to print every thread's
# stack; the exit status is cargo's either way.
set -u
log=$(mktemp)
status_file=$(mktemp)
trap 'rm -f "$log" "$status_file"' EXIT
{ ${CARGO:-cargo} test "$@"; echo $? > "$status_file"; } 2>&1 | tee "$log"
status=$(cat "$status_file")
[ "$status" = 0 ] && exit 0
crashed=$(sed -n "s/.*process didn't exit successfully: \`\([^\`]*\)\` (signal: .*/\1/p" "$log" | sort -u)
for bin in $crashed; do
    echo "cargo-test-or-backtrace: $bin died of a signal; once more under gdb for its stacks:" >&2
    if command -v gdb >/dev/null 2>&1; then
        gdb -batch -ex run -ex "thread apply all bt 25" --args "$bin" 2>&1 | grep -v "^\[New Thread\|^\[Thread" >&2
    else
        echo "cargo-test-or-backtrace: no gdb on this machine" >&2
    fi
done
exit "$status"
