#!/usr/bin/env bash
# Installs the shared libraries that the bpy and gmsh wheels link against, when they are
# missing and we may install them (root with apt-get). Everything else comes from pip.
set -euo pipefail
libs=(libX11.so.6 libXrender.so.1 libXfixes.so.3 libXi.so.6 libxkbcommon.so.0 libSM.so.6
      libGL.so.1 libXext.so.6 libGLU.so.1 libXcursor.so.1 libXft.so.2 libXinerama.so.1
      libfontconfig.so.1)
pkgs=(libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6
      libgl1 libxext6 libglu1-mesa libxcursor1 libxft2 libxinerama1
      libfontconfig1)
missing=()
for i in "${!libs[@]}"; do
  ldconfig -p 2>/dev/null | grep -q "${libs[$i]}" || missing+=("${pkgs[$i]}")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null; then
  echo "installing system libraries: ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "missing system libraries (install them with your package manager): ${missing[*]}" >&2
  exit 1
fi
