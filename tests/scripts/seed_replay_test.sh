#!/usr/bin/env bash
# A randomized test replays from its seed: runs one gtest twice with the same
# VKRC_TEST_SEED and passes only when both runs pass, both print that seed, and
# both print the same summary line (a line matching SUMMARY, which the test
# derives from every random choice it made).
# Usage: seed_replay_test.sh TEST_BINARY GTEST_FILTER SUMMARY_REGEX
set -uo pipefail
binary=$1 filter=$2 summary=$3
seed=20261127
run() {
    local output
    output=$(VKRC_TEST_SEED=$seed "$binary" --gtest_filter="$filter" 2>&1) || {
        printf '%s\n' "$output"
        echo "seed_replay_test.sh: $filter failed with VKRC_TEST_SEED=$seed" >&2
        return 1
    }
    grep -q "VKRC_TEST_SEED=$seed" <<<"$output" || {
        echo "seed_replay_test.sh: $filter did not print VKRC_TEST_SEED=$seed" >&2
        return 1
    }
    grep -E -- "$summary" <<<"$output" || {
        echo "seed_replay_test.sh: $filter printed no line matching /$summary/" >&2
        return 1
    }
}
first=$(run) || exit 1
second=$(run) || exit 1
echo "first run:  $first"
echo "second run: $second"
if [ "$first" != "$second" ]; then
    echo "seed_replay_test.sh: the same seed gave different runs" >&2
    exit 1
fi
