#!/bin/bash
# Views use only the public headers: each view source listed here includes
# <tactus/...>, system headers, and headers of its own folder, never a path
# into the rest of the tree ("../controllers/...", "../model/...").
#   test_view_headers.sh SOURCE_DIR
set -euo pipefail
src=$1
views=(views/graphics/graphics_view.c)
bad=0
for f in "${views[@]}"; do
  [ -f "$src/$f" ] || { echo "test_view_headers: $f is missing" >&2; exit 1; }
  dir=$(dirname "$src/$f")
  while IFS= read -r line; do
    inc=${line#*\"}
    inc=${inc%%\"*}
    case "$inc" in
    */*) echo "test_view_headers: $f includes \"$inc\", outside its own folder" >&2; bad=1 ;;
    *) [ -f "$dir/$inc" ] || { echo "test_view_headers: $f includes \"$inc\", not in its folder" >&2; bad=1; } ;;
    esac
  done < <(grep -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$src/$f" || true)
  # nothing of the internals through the back door either
  if grep -nE 'tx_param_json\(|json_t\b|tx_system_' "$src/$f" >&2; then
    echo "test_view_headers: $f uses an internal API (above)" >&2
    bad=1
  fi
done
[ $bad = 0 ] && echo "test_view_headers: ${#views[@]} view(s) use only public headers and their own folder"
exit $bad
