#!/usr/bin/env bash
# Install what crashfree needs and is missing: Debian packages for the build, Python packages
# for post-processing and regression tests. Idempotent and quick when everything is there.
# ParaView's readers and off-screen pictures (postproc/render_state.py, tests/regression/
# test_paraview.py) come with the `vtk` package of PyPI; it draws without a display through EGL,
# which Mesa's libraries give on a machine without a GPU (libegl1, libegl-mesa0, libgl1-mesa-dri).
# MPI domains (docs/parallel_scaling.md): Open MPI's compiler wrapper mpifort and launcher mpirun
# (libopenmpi-dev, openmpi-bin), installed also when the packages are there but the commands are
# not on the PATH.
set -euo pipefail

debian_packages=(gfortran make libhdf5-dev libmetis-dev liblapack-dev libopenblas-dev python3 python3-pip
                 libegl1 libegl-mesa0 libgl1-mesa-dri libopenmpi-dev openmpi-bin)
# the embedding examples and their test (docs/embedding.md): a C compiler, pkg-config, nm
debian_packages+=(gcc pkg-config binutils)
missing=()
for package in "${debian_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ! command -v mpifort >/dev/null || ! command -v mpirun >/dev/null; then
  for package in libopenmpi-dev openmpi-bin; do
    [[ " ${missing[*]} " == *" $package "* ]] || missing+=("$package")
  done
  # installed but not on the PATH: reinstall puts the alternatives (mpifort, mpirun) back
  reinstall_mpi=1
fi
if ((${#missing[@]})); then
  echo "crashfree: installing Debian packages: ${missing[*]}"
  sudo_prefix=""
  if [ "$(id -u)" -ne 0 ]; then sudo_prefix="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo_prefix apt-get update -qq
  $sudo_prefix apt-get install -y -qq "${missing[@]}" >/dev/null
  if [ -n "${reinstall_mpi:-}" ] && ! command -v mpifort >/dev/null; then
    $sudo_prefix apt-get install -y -qq --reinstall libopenmpi-dev openmpi-bin >/dev/null
  fi
fi
# the check that the MPI build can go ahead (as the Python imports below)
if ! command -v mpifort >/dev/null || ! command -v mpirun >/dev/null; then
  echo "crashfree: Open MPI's mpifort and mpirun are still missing after installing libopenmpi-dev and" \
       "openmpi-bin: the MPI build cannot be made" >&2
  exit 1
fi

python=${PYTHON:-python3}
if ! "$python" -c "import numpy, h5py, matplotlib, pytest, lasso.dyna, vtk" 2>/dev/null; then
  echo "crashfree: installing Python packages from postproc/requirements.txt"
  "$python" -m pip install -q -r postproc/requirements.txt 2>/dev/null \
    || "$python" -m pip install -q --break-system-packages -r postproc/requirements.txt
fi
