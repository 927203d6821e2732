# Sourced by bench-compare.sh and fleet-compare.sh (not run on its own): the Release build of a
# base commit in a git worktree under build/compare/, beside this tree's build/release.
#
#   build_both_trees BASE TARGET...
#
# Sets base_sha (BASE's short hash) and tree (its worktree, built in $tree/build), and builds the
# targets in both trees.
build_both_trees() {
  local base=$1
  shift
  base_sha=$(git rev-parse --short=10 "$base^{commit}")
  tree=build/compare/$base_sha
  if [ ! -d "$tree" ]; then
    mkdir -p build/compare
    git worktree prune  # a worktree removed with build/ leaves its registration behind
    git worktree add --detach "$tree" "$base_sha" >/dev/null
  fi
  # The base tree needs ../shared beside it, as the repository does.
  [ -e build/compare/shared ] || ln -s "$(cd .. && pwd)/shared" build/compare/shared
  local dir
  for dir in "$tree/build" build/release; do
    local src=.
    [ "$dir" = "$tree/build" ] && src=$tree
    cmake -S "$src" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBEACONLOC_WERROR=ON \
      -DBEACONLOC_BUILD_BENCHMARKS=ON >/dev/null
    cmake --build "$dir" -j 2 --target "$@"
  done
}
