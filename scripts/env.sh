# Sourced by the flexmech scripts: installs system prerequisites when missing and
# checks for the Rust toolchain. Not meant to be run on its own.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/scripts/setup.sh"
if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    echo "flexmech: no Rust toolchain found. Install it with rustup (https://rustup.rs)" >&2
    echo "  and run this command again." >&2
    exit 1
  fi
fi
cd "$ROOT"
