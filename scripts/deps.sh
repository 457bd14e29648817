#!/usr/bin/env bash
# Install the Debian 12 packages eical needs, only those missing; quiet when none is.
# Usage: scripts/deps.sh [build|test]   (test adds what only the test suite needs)
set -euo pipefail
# libsqlite3-dev, libpq-dev: the calibration history (SQLite on the control PC, PostgreSQL client).
build_pkgs=(g++ cmake ninja-build pkg-config libeigen3-dev libtomlplusplus-dev libcli11-dev
  nlohmann-json3-dev zlib1g-dev libzstd-dev libsystemd-dev libusb-1.0-0-dev libgpiod-dev
  cyclonedds-dev cyclonedds-tools libgtest-dev libbenchmark-dev libboost-dev dpkg-dev
  libsqlite3-dev libpq-dev)
# chromium + fonts: the report screenshot test; linuxcnc-uspace: the end-to-end test with a
# real NC (tests/linuxcnc), Depends only; postgresql: the history tests and benchmark start a
# server of their own (initdb/postgres from /usr/lib/postgresql/<version>/bin; as root they
# run it as user nobody, initdb refuses root). dpkg-dev (build): the .deb's library
# dependencies (dpkg-shlibdeps, `--target package`). clang + libclang-rt-14-dev: the
# sanitizer stage (the ASan + UBSan tests and libFuzzer, fuzz/, in one clang tree).
# clang-format + clang-tidy (run-clang-tidy): the style stage (scripts/check-style,
# .clang-format, .clang-tidy).
test_pkgs=(systemd chromium fonts-dejavu-core linuxcnc-uspace postgresql clang libclang-rt-14-dev clang-format
  clang-tidy)
want=("${build_pkgs[@]}")
[[ "${1:-build}" == test ]] && want+=("${test_pkgs[@]}")

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
((${#missing[@]} == 0)) && exit 0

echo "eical: installing missing Debian packages: ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "eical: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
