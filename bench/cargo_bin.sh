# Sourced by the bench scripts (issue 31): where cargo puts the release build, never a fixed
# target/release (CARGO_TARGET_DIR, .cargo/config or the workspace's own target/ all count).
#   release_dir      the release output folder of the target directory `cargo metadata` reports
#   endocast_binary  sets $endocast: $ENDOCAST when set (any build of the binary), else the
#                    release build, built first
release_dir="$(cargo metadata --format-version 1 --no-deps |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release"
endocast_binary() {
  if [ -n "${ENDOCAST:-}" ]; then
    endocast=$ENDOCAST
  else
    cargo build --release -q -p endocast-cli
    endocast=$release_dir/endocast
  fi
}
