#!/usr/bin/env bash
# Runs every test: `cargo test --all-features`, with any arguments passed through
# (e.g. `tests/run.sh --release`, `tests/run.sh --release -- fuzz`).
#
# The `mpfr` feature builds GMP and MPFR from source, and GMP's build needs `m4`. When `m4` is
# missing, this script installs it with apt-get (through sudo when not root), and otherwise
# stops with a message saying what is missing and how to get it. `cargo test` without
# `--all-features` does not need `m4`.
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf 'tests/run.sh: %s\n' "$*" >&2; }

# fail_m4 WHAT [HOW]: what is wrong, what to do about it (by default: how to install m4).
fail_m4() {
  say "error: $1"
  say "${2:-install m4 (Debian/Ubuntu: 'apt-get install m4', Fedora: 'dnf install m4', macOS: 'brew install m4') and rerun.}"
  say "(GMP, built from source for the 'mpfr' feature, needs m4; 'cargo test' without --all-features does not.)"
  exit 1
}

if ! command -v cargo >/dev/null 2>&1; then
  say "error: cargo is not on PATH ($PATH); install Rust (https://rustup.rs) or add ~/.cargo/bin to PATH."
  exit 1
fi

if ! command -v m4 >/dev/null 2>&1; then
  say "m4 is missing (GMP's build for the 'mpfr' feature needs it)"
  if ! command -v apt-get >/dev/null 2>&1; then
    fail_m4 "m4 is missing and apt-get is not available to install it."
  fi
  if [ "$(id -u)" -eq 0 ]; then
    as_root=()
  elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    fail_m4 "m4 is missing, and installing it needs root: this is not root and sudo is not available."
  fi
  say "installing m4: ${as_root[*]:+${as_root[*]} }apt-get install -y m4"
  if ! { "${as_root[@]}" apt-get update -qq && "${as_root[@]}" apt-get install -y -qq m4; } >&2; then
    fail_m4 "'${as_root[*]:+${as_root[*]} }apt-get install -y m4' failed."
  fi
  # apt-get succeeds when m4 is already installed, and installs into /usr/bin: check that the
  # build will actually find it on this PATH.
  if ! command -v m4 >/dev/null 2>&1; then
    installed=""
    if command -v dpkg >/dev/null 2>&1; then
      installed=$(dpkg -L m4 2>/dev/null | grep -m1 '/bin/m4$' || true)
    fi
    if [ -n "$installed" ]; then
      fail_m4 "m4 is installed at $installed, but $(dirname "$installed") is not on PATH ($PATH)." \
        "add it to PATH (export PATH=\"\$PATH:$(dirname "$installed")\") and rerun."
    fi
    fail_m4 "apt-get reported success, but m4 is still not on PATH ($PATH)."
  fi
  say "m4 installed: $(command -v m4)"
fi

exec cargo test --all-features "$@"
