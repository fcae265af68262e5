#!/usr/bin/env bash
# `apt_install PACKAGE`: installs a Debian package quietly, as root or through sudo. Sourced by
# scripts/ci-deps.sh and scripts/viewer-deps.sh.
apt_install() {
  local sudo=""
  if [ "$(id -u)" != 0 ]; then sudo=sudo; fi
  $sudo apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}
