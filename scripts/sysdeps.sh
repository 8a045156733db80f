#!/usr/bin/env bash
# System packages locust needs beyond PyPI, installed when we can (root + apt), otherwise
# named with the exact line to run. Called by `make demo` and `make test`.
#   libosmesa6  offscreen OpenGL for MuJoCo rendering (MUJOCO_GL=osmesa)
#   librecad    opens the generated DXF files headless in the fab tests (librecad dxf2pdf)
#   chromium    opens the HTML report in a real browser in the report test
set -u
pkgs="libosmesa6 librecad chromium"
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then
  echo "installing system packages:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq >/dev/null && apt-get install -y -qq --no-install-recommends $missing >/dev/null \
    || { echo "apt-get install failed; run: sudo apt-get install -y$missing" >&2; exit 1; }
else
  echo "missing system packages:$missing" >&2
  echo "install them with: sudo apt-get install -y$missing" >&2
  echo "(tests that need them are skipped, with this reason, until then)" >&2
fi
