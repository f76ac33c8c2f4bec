#!/usr/bin/env bash
# Installs what flexmech needs from the system: the HDF5 C library (headers and
# pkg-config file) and pkg-config itself. Safe to run repeatedly: it does nothing
# when the library is already found. Needs root (or sudo) on Debian/Ubuntu; users
# without root can build with `--features hdf5-static` instead (docs/book/without-root.md).
set -euo pipefail

have_hdf5() {
  command -v pkg-config >/dev/null 2>&1 && pkg-config --exists hdf5 2>/dev/null && return 0
  # Debian's serial flavour ships its .pc under a multiarch directory pkg-config knows.
  [ -f /usr/include/hdf5/serial/hdf5.h ] && command -v pkg-config >/dev/null 2>&1
}

if have_hdf5; then
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "flexmech setup: the HDF5 library is missing and this user is not root." >&2
    echo "  Install it with your package manager (Debian/Ubuntu: libhdf5-dev pkg-config)," >&2
    echo "  or build with: cargo build --release --features hdf5-static" >&2
    exit 1
  fi
fi

if command -v apt-get >/dev/null 2>&1; then
  echo "flexmech setup: installing libhdf5-dev and pkg-config (apt-get)..." >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends libhdf5-dev pkg-config >/dev/null
else
  echo "flexmech setup: no apt-get here; install the HDF5 development library" >&2
  echo "  (headers + pkg-config file) with your package manager and run again." >&2
  exit 1
fi

if ! have_hdf5; then
  echo "flexmech setup: HDF5 still not found after installing; check pkg-config --exists hdf5" >&2
  exit 1
fi
