"""Helpers of the output tests: a small deck that writes many states, a C shim that plays a
small disk (compiled with gcc into the test's directory), a tmpfs mount when running as root,
and readers that say what a results file and its XDMF companion hold."""
from __future__ import annotations

import os
import shutil
import subprocess
import xml.etree.ElementTree as ElementTree
from contextlib import contextmanager
from pathlib import Path

import h5py

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

# A small disk for the tests: files opened with open() under $CRASHFREE_TEST_DISK_DIR may take
# $CRASHFREE_TEST_DISK_BYTES bytes together; a write that would need more fails with ENOSPC, as
# on a full disk. With $CRASHFREE_TEST_NO_FALLOCATE set, fallocate fails with EOPNOTSUPP (a file
# system without it). $CRASHFREE_TEST_WRITE_LOG names a file that receives, at exit, the bytes
# written to those files (write and pwrite, which HDF5 uses).
DISK_SHIM_SOURCE = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#define MAX_FD 4096
static long long used, written, extent[MAX_FD];
static char tracked[MAX_FD];

static void track(int fd, const char *path) {
  const char *dir = getenv("CRASHFREE_TEST_DISK_DIR");
  struct stat st;
  if (fd < 0 || fd >= MAX_FD || !dir || strncmp(path, dir, strlen(dir)) != 0) return;
  tracked[fd] = 1;
  extent[fd] = fstat(fd, &st) == 0 ? (long long)st.st_size : 0;
}

static int allocate(int fd, long long end, size_t count) {
  const char *capacity = getenv("CRASHFREE_TEST_DISK_BYTES");
  if (fd < 0 || fd >= MAX_FD || !tracked[fd]) return 0;
  written += (long long)count;
  if (end <= extent[fd]) return 0;
  if (capacity && used + (end - extent[fd]) > atoll(capacity)) {
    errno = ENOSPC;
    return -1;
  }
  used += end - extent[fd];
  extent[fd] = end;
  return 0;
}

#define REAL(name) static __typeof__(name) *real; if (!real) real = dlsym(RTLD_NEXT, #name)

int open(const char *path, int flags, ...) {
  REAL(open);
  mode_t mode = 0;
  if (flags & O_CREAT) { va_list a; va_start(a, flags); mode = va_arg(a, mode_t); va_end(a); }
  int fd = real(path, flags, mode);
  track(fd, path);
  return fd;
}

int open64(const char *path, int flags, ...) {
  REAL(open64);
  mode_t mode = 0;
  if (flags & O_CREAT) { va_list a; va_start(a, flags); mode = va_arg(a, mode_t); va_end(a); }
  int fd = real(path, flags, mode);
  track(fd, path);
  return fd;
}

ssize_t pwrite(int fd, const void *buffer, size_t count, off_t offset) {
  REAL(pwrite);
  if (allocate(fd, (long long)offset + (long long)count, count)) return -1;
  return real(fd, buffer, count, offset);
}

ssize_t pwrite64(int fd, const void *buffer, size_t count, off64_t offset) {
  REAL(pwrite64);
  if (allocate(fd, (long long)offset + (long long)count, count)) return -1;
  return real(fd, buffer, count, offset);
}

ssize_t write(int fd, const void *buffer, size_t count) {
  REAL(write);
  if (fd >= 0 && fd < MAX_FD && tracked[fd]) {
    off_t position = lseek(fd, 0, SEEK_CUR);
    if (position >= 0 && allocate(fd, (long long)position + (long long)count, count)) return -1;
  }
  return real(fd, buffer, count);
}

int fallocate(int fd, int mode, off_t offset, off_t length) {
  REAL(fallocate);
  if (getenv("CRASHFREE_TEST_NO_FALLOCATE")) { errno = EOPNOTSUPP; return -1; }
  return real(fd, mode, offset, length);
}

int close(int fd) {
  REAL(close);
  if (fd >= 0 && fd < MAX_FD) tracked[fd] = 0;
  return real(fd);
}

__attribute__((destructor)) static void report(void) {
  const char *log = getenv("CRASHFREE_TEST_WRITE_LOG");
  if (!log) return;
  FILE *file = fopen(log, "w");
  if (file) { fprintf(file, "%lld\n", written); fclose(file); }
}
"""


def cube_deck(path: Path, states: int, end_time: float = 1.0) -> Path:
    """8 elastic steel hexahedra (1 mm cube) flying at 1 mm/ms: about 14,000 cycles per ms,
    `states` states (and glstat rows) over `end_time`."""
    nodes, elements = block_mesh((2, 2, 2), (1.0, 1.0, 1.0))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / states),
        "*DATABASE_GLSTAT\n" + fields(end_time / states),
        "*PART\ncube\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.0, 1.0, 0.0, 0.0) + "\n" +
        fields(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        nodes_card(nodes),
        solids_card(elements),
    )


def compile_disk_shim(directory: Path) -> Path:
    """The shim as a shared library in `directory` (the test is skipped without gcc)."""
    import pytest
    compiler = shutil.which("gcc")
    if compiler is None:
        pytest.skip("gcc is needed to build the disk shim")
    source = directory / "disk_shim.c"
    library = directory / "disk_shim.so"
    source.write_text(DISK_SHIM_SOURCE)
    subprocess.run([compiler, "-shared", "-fPIC", "-O1", "-o", str(library), str(source), "-ldl"],
                   check=True, capture_output=True)
    return library


def run_solver(binary: Path, deck: Path, output: Path, environment: dict | None = None,
               timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run([str(binary), f"i={deck}", f"outdir={output}", "ncpu=1"],
                          capture_output=True, text=True, timeout=timeout,
                          env=dict(os.environ, OMP_NUM_THREADS="1", **(environment or {})))


def xdmf_state_count(path: Path) -> int:
    """States listed by an XDMF file; raises when it is not well-formed XML."""
    root = ElementTree.parse(path).getroot()
    return len(root.find("Domain").find("Grid").findall("Grid"))


def readable_states(path: Path) -> tuple[int, int, str]:
    """(states listed, states whose datasets and time all read, /run status)."""
    with h5py.File(path, "r") as results:
        names = sorted(results["states"])
        readable = 0
        for name in names:
            try:
                state = results["states"][name]
                for dataset in ("displacement", "velocity", "solid_stress", "solid_plastic_strain"):
                    state[dataset][()]
                state.attrs["time"]
                readable += 1
            except (KeyError, OSError, RuntimeError):
                pass
        return len(names), readable, results["run"].attrs["status"]


@contextmanager
def tmpfs(mount_point: Path, options: str):
    """A tmpfs mounted at `mount_point` (root only; the caller skips otherwise)."""
    mount_point.mkdir(parents=True, exist_ok=True)
    subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mount_point)], check=True,
                   capture_output=True)
    try:
        yield mount_point
    finally:
        subprocess.run(["umount", "-l", str(mount_point)], capture_output=True)


def can_mount() -> bool:
    return os.geteuid() == 0 and shutil.which("mount") is not None
