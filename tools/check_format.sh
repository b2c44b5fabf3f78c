#!/usr/bin/env bash
# Formatting check: every C++ file under src/, tests/ and bench/ must be as clang-format
# (with the repository's .clang-format) would write it. Lists the files that differ and exits
# 1; exits 0 when none does. Fix with:  clang-format -i FILE...
# CLANG_FORMAT names the program (default clang-format; the config is written for version 14,
# and other versions may format some constructs differently).
set -euo pipefail
cd "$(dirname "$0")/.."
clang_format="${CLANG_FORMAT:-clang-format}"
if ! command -v "$clang_format" >/dev/null; then
  echo "check_format: $clang_format not found (Debian: apt-get install clang-format)" >&2
  exit 2
fi
version="$("$clang_format" --version | sed -n 's/.*version \([0-9]*\).*/\1/p')"
[ "$version" = 14 ] || echo "check_format: $clang_format is version ${version:-?}, the config is for 14" >&2

mapfile -t files < <(git ls-files --cached --others --exclude-standard -- 'src/*.cpp' 'src/*.hpp' 'tests/*.cpp' 'tests/*.hpp' 'bench/*.cpp' 'bench/*.hpp')
differ=()
for f in "${files[@]}"; do
  "$clang_format" --dry-run --Werror "$f" >/dev/null 2>&1 || differ+=("$f")
done
if ((${#differ[@]})); then
  printf '%s\n' "${differ[@]}"
  echo "check_format: ${#differ[@]} of ${#files[@]} files are not formatted (clang-format -i FILE...)" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted" >&2
