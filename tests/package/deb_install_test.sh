#!/usr/bin/env bash
# The Debian package as a machine builder installs it: build it with CPack, install it with
# dpkg -i, check the installed service (eicald --check with the installed configuration,
# systemd-analyze verify of the installed unit, the user and the recording path), then
# purge it. Needs root (CI runs as root); exit 77 (skipped) otherwise.
# Usage: deb_install_test.sh BUILD_DIR
set -euo pipefail
build=$1
[[ $(id -u) -eq 0 ]] || { echo "not root: the package is not installed here (skipped)"; exit 77; }
fail() { echo "FAIL: $*" >&2; exit 1; }

# One dpkg at a time on this host (other checkouts run the same test).
exec 9>/tmp/eical-dpkg.lock
flock 9

version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
arch=$(dpkg --print-architecture)
deb="$build/eical_${version}_${arch}.deb"
rm -f "$deb"
cmake --build "$build" --target package >"$build/package.log" 2>&1 || { tail -30 "$build/package.log"; fail "cmake --build --target package"; }
[[ -f $deb ]] || fail "no $deb (CPack wrote: $(ls "$build"/*.deb 2>/dev/null))"
echo "built $deb"

# The package's contents and control data.
contents=$(dpkg-deb -c "$deb")
for f in ./usr/bin/eicald ./usr/bin/eical ./lib/systemd/system/eicald.service ./etc/eical/eicald.toml ./etc/eical/cyclonedds.xml \
         ./usr/share/doc/eical/README.md ./usr/share/doc/eical/docs/first-calibration.md \
         ./usr/share/man/man1/eical.1 ./usr/share/man/man8/eicald.8 ./usr/share/man/man5/eicald.toml.5 \
         ./usr/share/eical/integrations/linuxcnc/mcodes/M101; do
  grep -q " $f\$" <<<"$contents" || fail "$f is not in the package"
done
conffiles=$(dpkg-deb -I "$deb" conffiles)
for f in /etc/eical/eicald.toml /etc/eical/cyclonedds.xml; do
  grep -qx "$f" <<<"$conffiles" || fail "$f is not a conffile"
done
dpkg-deb -f "$deb" Depends | grep -q libddsc || fail "Depends misses Cyclone DDS: $(dpkg-deb -f "$deb" Depends)"

had_user=0; getent passwd eical >/dev/null && had_user=1
had_state=0; [[ -e /var/lib/eical ]] && had_state=1
cleanup() {
  dpkg --purge eical >/dev/null 2>&1 || true
  ((had_user)) || userdel eical >/dev/null 2>&1 || true
  ((had_state)) || rm -rf /var/lib/eical
}
trap cleanup EXIT

DEBIAN_FRONTEND=noninteractive dpkg -i "$deb" || fail "dpkg -i (missing dependencies? apt-get -f install)"
getent passwd eical >/dev/null || fail "postinst made no eical user"
[[ $(stat -c %U /var/lib/eical/runs) == eical ]] || fail "/var/lib/eical/runs is not the eical user's"
# The installed configuration, as the unit starts it (its environment names the DDS XML).
CYCLONEDDS_URI=file:///etc/eical/cyclonedds.xml /usr/bin/eicald --check --config /etc/eical/eicald.toml || fail "eicald --check"
out=$(systemd-analyze verify /lib/systemd/system/eicald.service 2>&1) || fail "systemd-analyze verify: $out"
if grep -q "eicald.service" <<<"$out"; then fail "systemd-analyze verify complains: $out"; fi
/usr/bin/eical --help >/dev/null || fail "eical --help"
echo "installed, checked and verified: $deb"
