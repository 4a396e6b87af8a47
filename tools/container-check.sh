#!/usr/bin/env bash
# Check the Dockerfile without Docker: run its steps in a Debian bookworm chroot.
#
#   tools/container-check.sh [--root DIR] [--python DIR] [--fresh] [--keep-venv] [--smoke] [-- CMD...]
#
# What python:3.12-slim-bookworm gives and what the Dockerfile adds, rebuilt here:
#  1. DIR (default /var/tmp/bcfem-container-root, outside any work tree): a Debian
#     bookworm *minbase* root from debootstrap, which is what debian:bookworm-slim is
#     made of. Kept between runs: a rerun skips debootstrap and finds the .deb files
#     and pip's cache in place (--fresh starts over). --keep-venv also keeps the
#     last run's .venv (bootstrap.sh then reinstalls only if pyproject.toml or the
#     constraints changed); without it .venv is installed afresh, as docker build does.
#  2. The python image's layer: BASE_PACKAGES below (ca-certificates, netbase, tzdata
#     and the Debian libraries CPython's own extension modules link) and a Python of
#     the FROM line's version. CPython cannot be downloaded here, so the host's pyenv
#     build (/root/.pyenv/versions/3.12.x, else --python DIR) is copied into the root
#     at the same path (its RUNPATH is absolute) and linked as
#     /usr/local/bin/python3.12 etc., where the image has python.org's build; `ldd`
#     of it and its lib-dynload modules must find every library in the root.
#  3. The Dockerfile itself, read instruction by instruction so the two cannot drift:
#     ARG values are exported to the RUN lines, RUN lines run with /bin/sh -c in the
#     chroot (the apt-get line installs "$APT_PACKAGES"), COPY . . copies the work
#     tree as git sees it (tracked files plus untracked ones that are not ignored,
#     with their uncommitted edits; no .venv, no mesh caches) to WORKDIR, ENV sets
#     the environment of what follows. Any other instruction is an error here.
#     Packages installed by an earlier run but no longer listed are purged first.
#  4. With the final ENV: ldd of the gmsh wheel's libgmsh.so* and of every .so in
#     .venv must find all libraries (their system ones are printed with the
#     package that owns them); `import gmsh, pyvista, dolfinx`; gmsh meshes a disk;
#     pyvista renders off screen through EGL and saves a screenshot (copied to
#     DIR.screenshot.png), listing the GL libraries the process loaded.
#  5. The Dockerfile's CMD (make test), or CMD... given after --; --smoke stops
#     after step 4.
# Exits non-zero when any step fails. Needs root, debootstrap on the host
# (apt-get install -y debootstrap) and Debian's package mirror and PyPI.
# Not part of CI: docs/docker.md.
set -euo pipefail

REPO=$(cd "$(dirname "$0")/.." && pwd)
ROOT=/var/tmp/bcfem-container-root
PY_SRC=
FRESH=0
SMOKE=0
KEEP_VENV=0
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
USER_CMD=()
while [ $# -gt 0 ]; do
  case "$1" in
    --root) ROOT=$2; shift 2 ;;
    --python) PY_SRC=$2; shift 2 ;;
    --fresh) FRESH=1; shift ;;
    --smoke) SMOKE=1; shift ;;
    --keep-venv) KEEP_VENV=1; shift ;;
    --) shift; USER_CMD=("$@"); break ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "container-check: unknown argument $1 (--help)" >&2; exit 2 ;;
  esac
done

# The python image's own Debian packages: ca-certificates, netbase, tzdata, and the
# run-time libraries of CPython's extension modules (ssl, sqlite3, ctypes, bz2, lzma,
# readline, curses, uuid, zlib, pyexpat, nis, crypt) that its Dockerfile keeps.
# Nothing here provides what the Dockerfile must install itself (no X, GL or fonts).
BASE_PACKAGES="ca-certificates netbase tzdata libbz2-1.0 libcrypt1 libexpat1 libffi8
  liblzma5 libncursesw6 libnsl2 libreadline8 libsqlite3-0 libssl3 libtinfo6 libtirpc3
  libuuid1 zlib1g"
BASE_PACKAGES=$(echo $BASE_PACKAGES)
# the image's environment (docker inspect python:3.12-slim-bookworm), less GPG_KEY
IMAGE_PATH=/usr/local/bin:/usr/local/sbin:/usr/sbin:/usr/bin:/sbin:/bin

die() { echo "container-check: $*" >&2; exit 1; }
T0=$SECONDS
step() { printf '\n== [%s] %s\n' "$(date -u +%H:%M:%S) +$((SECONDS - T0))s" "$*"; }

[ "$(id -u)" = 0 ] || die "needs root (debootstrap, chroot, mount)"
command -v debootstrap >/dev/null || die "no debootstrap: apt-get update && apt-get install -y debootstrap"
mkdir -p "$(dirname "$ROOT")"
ROOT=$(cd "$(dirname "$ROOT")" && pwd)/$(basename "$ROOT")
if git -C "$(dirname "$ROOT")" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  die "--root $ROOT is inside a git work tree; put it elsewhere"
fi

# --- the Dockerfile, one instruction a line (continuations joined, comments dropped)
mapfile -t INSTR < <(awk '
  /^[[:space:]]*#/ { next }
  { l = $0; cont = sub(/\\[[:space:]]*$/, "", l)
    buf = (buf == "" ? l : buf " " l)
    if (cont) next
    if (buf ~ /[^[:space:]]/) print buf
    buf = "" }
  END { if (buf ~ /[^[:space:]]/) print buf }' "$REPO/Dockerfile")
unquote() { local v=$1; v=${v#\"}; v=${v%\"}; echo "$v" | tr -s ' \t' '  '; }
FROM=
APT_PACKAGES=
for i in "${INSTR[@]}"; do
  read -r kw rest <<<"$i"
  case "${kw^^}" in
    FROM) FROM=$rest ;;
    ARG) [ "${rest%%=*}" = APT_PACKAGES ] && APT_PACKAGES=$(unquote "${rest#*=}") ;;
  esac
done
[[ $FROM =~ ^python:([0-9]+\.[0-9]+)-slim-bookworm$ ]] \
  || die "FROM $FROM: this check rebuilds python:X.Y-slim-bookworm only"
PY_VER=${BASH_REMATCH[1]}
if [ -z "$PY_SRC" ]; then
  PY_SRC=$(ls -d /root/.pyenv/versions/"$PY_VER".* 2>/dev/null | sort -V | tail -1 || true)
  [ -n "$PY_SRC" ] || die "no /root/.pyenv/versions/$PY_VER.*: give a CPython $PY_VER build with --python DIR"
fi
PY_SRC=$(cd "$PY_SRC" && pwd)
[ -x "$PY_SRC/bin/python$PY_VER" ] || die "$PY_SRC/bin/python$PY_VER missing"
echo "container-check: root $ROOT, Python $("$PY_SRC/bin/python$PY_VER" -V 2>&1) from $PY_SRC"
echo "container-check: Dockerfile APT_PACKAGES: $APT_PACKAGES"

# one run per root at a time
exec 9>"$ROOT.lock"
flock -n 9 || die "another container-check is using $ROOT"

# --- mounts, and their cleanup however the script ends
MOUNTS=()
cleanup() {
  local p pid
  for p in /proc/[0-9]*; do   # processes still running in the root (e.g. an MPI rank)
    [ "$(readlink "$p/root" 2>/dev/null)" = "$ROOT" ] || continue
    pid=${p#/proc/}; kill "$pid" 2>/dev/null || true
  done
  for ((i = ${#MOUNTS[@]} - 1; i >= 0; i--)); do
    umount -R "${MOUNTS[i]}" 2>/dev/null || umount -R -l "${MOUNTS[i]}" || true
  done
  MOUNTS=()
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
mount_root() {
  local d
  for d in proc dev sys; do
    if mountpoint -q "$ROOT/$d"; then   # left over by a killed run
      mount --make-rslave "$ROOT/$d"; umount -R -l "$ROOT/$d"
    fi
    case $d in
      proc) mount -t proc proc "$ROOT/proc" ;;
      *) mount --rbind "/$d" "$ROOT/$d"; mount --make-rslave "$ROOT/$d" ;;
    esac
    MOUNTS+=("$ROOT/$d")
  done
}
# run a shell command in the root with a clean environment: in_root ENV_ARRAY_NAME CMD
in_root() {
  local -n envref=$1
  chroot "$ROOT" /usr/bin/env -i "${envref[@]}" /bin/sh -c "$2" </dev/null
}

# --- 1. the bookworm minbase root
if [ "$FRESH" = 1 ] && [ -e "$ROOT" ]; then
  step "--fresh: removing $ROOT"
  for d in proc dev sys; do
    if mountpoint -q "$ROOT/$d"; then mount --make-rslave "$ROOT/$d"; umount -R -l "$ROOT/$d"; fi
  done
  rm -rf --one-file-system "$ROOT"
fi
STATE=$ROOT/.container-check
if [ ! -e "$STATE/baseline" ]; then
  step "debootstrap --variant=minbase bookworm $ROOT $MIRROR"
  rm -rf --one-file-system "$ROOT"
  debootstrap --variant=minbase bookworm "$ROOT" "$MIRROR"
  mkdir -p "$STATE"
  chroot "$ROOT" dpkg-query -W -f '${Package}\n' | sort >"$STATE/baseline"
fi
# as the debian image: bookworm with its updates and security suites
printf 'deb %s bookworm main\ndeb %s bookworm-updates main\ndeb %s bookworm-security main\n' \
  "$MIRROR" "$MIRROR" "${MIRROR%/debian}/debian-security" >"$ROOT/etc/apt/sources.list"
cp -L /etc/resolv.conf "$ROOT/etc/resolv.conf"
mount_root

# --- 2. the python image's layer
step "python image layer: $(echo $BASE_PACKAGES | wc -w) Debian packages and Python $PY_VER"
APT_ENV=(HOME=/root LANG=C.UTF-8 PATH=$IMAGE_PATH DEBIAN_FRONTEND=noninteractive)
in_root APT_ENV "apt-get update -qq"
# Only the baseline, BASE_PACKAGES and the Dockerfile's list may stay from earlier runs.
installed=$(chroot "$ROOT" dpkg-query -W -f '${db:Status-Abbrev} ${Package}\n' | awk '$1 == "ii" {print $2}' | sort)
extra=$(comm -13 "$STATE/baseline" <(echo "$installed") | tr '\n' ' ')
keep=$(comm -12 <(echo $BASE_PACKAGES $APT_PACKAGES | tr ' ' '\n' | sort -u) <(echo "$installed") | tr '\n' ' ')
[ -z "$extra" ] || in_root APT_ENV "apt-mark auto $extra >/dev/null"
[ -z "$keep" ] || in_root APT_ENV "apt-mark manual $keep >/dev/null"
# the debian image is rebuilt with bookworm's updates: upgrade debootstrap's packages too
in_root APT_ENV "apt-get upgrade -y -qq >/dev/null && apt-get install -y -qq --no-install-recommends $BASE_PACKAGES >/dev/null"
in_root APT_ENV "apt-get autoremove -y -qq --purge -o APT::AutoRemove::RecommendsImportant=false \
  -o APT::AutoRemove::SuggestsImportant=false"
# Where the host reaches PyPI through a TLS-intercepting proxy it trusts that CA
# locally; the root needs the same to download wheels (and pip, which uses certifi's
# bundle before the venv's pip is upgraded, is pointed at the system bundle).
LOCAL_CA=0
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  cp /usr/local/share/ca-certificates/*.crt "$ROOT/usr/local/share/ca-certificates/"
  in_root APT_ENV "update-ca-certificates >/dev/null"
  LOCAL_CA=1
fi
if [ ! -x "$ROOT$PY_SRC/bin/python$PY_VER" ]; then
  echo "copying $PY_SRC into the root (without the host's site-packages/*.pth hooks)"
  mkdir -p "$ROOT$PY_SRC"
  tar -C "$PY_SRC" --exclude='./lib/python*/site-packages/*.pth' -cf - . | tar -C "$ROOT$PY_SRC" -xf -
fi
for n in "python$PY_VER" python3 python "pip$PY_VER" pip3 pip; do
  [ -e "$ROOT$PY_SRC/bin/$n" ] && ln -sfn "$PY_SRC/bin/$n" "$ROOT/usr/local/bin/$n"
done
in_root APT_ENV "
  missing=\$( { ldd $PY_SRC/bin/python$PY_VER
               for f in $PY_SRC/lib/python$PY_VER/lib-dynload/*.so; do
                 case \$f in *_tkinter*) continue ;; esac; ldd \$f; done; } | grep 'not found' | sort -u)
  if [ -n \"\$missing\" ]; then echo \"Python's libraries missing in the root:\"; echo \"\$missing\"; exit 1; fi
  python$PY_VER -c 'import ssl, sqlite3, ctypes, bz2, lzma, readline, uuid, zlib, pyexpat; print(\"python\", __import__(\"sys\").version.split()[0], \"links all its libraries\")'"

# --- 3. the Dockerfile
RUN_ENV=(HOME=/root LANG=C.UTF-8 PATH=$IMAGE_PATH "PYTHON_VERSION=$("$PY_SRC/bin/python$PY_VER" -c 'import platform; print(platform.python_version())')")
[ -z "${PIP_DEFAULT_TIMEOUT:-}" ] || RUN_ENV+=("PIP_DEFAULT_TIMEOUT=$PIP_DEFAULT_TIMEOUT")  # the host's, if slow
[ "$LOCAL_CA" = 0 ] || RUN_ENV+=(PIP_CERT=/etc/ssl/certs/ca-certificates.crt)
setenv() {  # setenv NAME VALUE: replace or add in RUN_ENV
  local i
  for i in "${!RUN_ENV[@]}"; do
    if [ "${RUN_ENV[i]%%=*}" = "$1" ]; then RUN_ENV[i]="$1=$2"; return; fi
  done
  RUN_ENV+=("$1=$2")
}
getenv() { local e; for e in "${RUN_ENV[@]}"; do [ "${e%%=*}" = "$1" ] && { echo "${e#*=}"; return; }; done; true; }
WORKDIR=/
CMD=()
for i in "${INSTR[@]}"; do
  read -r kw rest <<<"$i"
  case "${kw^^}" in
    FROM) ;;
    ARG) setenv "${rest%%=*}" "$(unquote "${rest#*=}")" ;;
    ENV)
      set -f
      for kv in $rest; do
        [[ $kv == *=* ]] || die "ENV $rest: only NAME=VALUE pairs are read"
        v=$(unquote "${kv#*=}"); cur=$(getenv "${kv%%=*}")
        v=${v//\$\{${kv%%=*}\}/$cur}; v=${v//\$${kv%%=*}/$cur}
        setenv "${kv%%=*}" "$v"
      done
      set +f ;;
    WORKDIR) WORKDIR=$rest; mkdir -p "$ROOT$WORKDIR" ;;
    COPY)
      [ "$rest" = ". ." ] || die "COPY $rest: only 'COPY . .' is mirrored"
      step "COPY . . -> $WORKDIR (the work tree as git sees it)"
      if [ "$KEEP_VENV" = 1 ] && [ -d "$ROOT$WORKDIR/.venv" ]; then
        find "$ROOT$WORKDIR" -mindepth 1 -maxdepth 1 ! -name .venv -exec rm -rf --one-file-system {} +
      else
        rm -rf --one-file-system "${ROOT:?}$WORKDIR"; mkdir -p "$ROOT$WORKDIR"
      fi
      (cd "$REPO" && git ls-files -z --cached --others --exclude-standard \
        | while IFS= read -r -d '' f; do [ -e "$f" ] && printf '%s\0' "$f"; done \
        | tar --null -T - -cf -) | tar -C "$ROOT$WORKDIR" -xf -
      echo "$(find "$ROOT$WORKDIR" -type f | wc -l) files" ;;
    RUN)
      step "RUN $rest"
      in_root RUN_ENV "cd '$WORKDIR' && $rest" || die "RUN failed: $rest" ;;
    CMD)
      [[ $rest =~ ^\[(.*)\]$ ]] || die "CMD $rest: only the exec form is read"
      set -f; read -r -a CMD <<<"$(echo "${BASH_REMATCH[1]}" | tr -d '",')"; set +f ;;
    *) die "Dockerfile instruction $kw is not mirrored by this check" ;;
  esac
done

# --- 4. what the wheels load, and whether it works
step "libraries of the wheels (ldd in the root) and off-screen rendering"
cat >"$ROOT/tmp/container-check-render.py" <<'EOF'
import os, sys
import bcfem, gmsh, pyvista, dolfinx  # bcfem first: it loads mpi4py's libmpi, which dolfinx needs
print("imports: gmsh", gmsh.__version__, "pyvista", pyvista.__version__, "dolfinx", dolfinx.__version__)
gmsh.initialize(interruptible=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addDisk(0, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
gmsh.model.mesh.generate(2)
ntri = sum(len(t) for t in gmsh.model.mesh.getElements(2)[1])
gmsh.finalize()
assert ntri > 10, ntri
print(f"gmsh: meshed a disk into {ntri} triangles")

import numpy as np
pl = pyvista.Plotter(off_screen=True, window_size=(400, 300))
pl.add_mesh(pyvista.Sphere(), color="red")
img = pl.screenshot(sys.argv[1], return_img=True)
rw = pl.render_window
cls = rw.GetClassName()
caps = rw.ReportCapabilities()
libs = sorted({l.split()[-1] for l in open("/proc/self/maps") if "/" in l and any(k in l for k in (
    "libEGL", "libGL", "libgbm", "/dri/", "libX", "libglapi", "libgmsh", "libfontconfig", "libgomp"))})
pl.close()
renderer = next((l.split(":", 1)[1].strip() for l in caps.splitlines() if "renderer string" in l), "?")
red = int(((img[..., 0] > 150) & (img[..., 1] < 100)).sum())
print(f"pyvista: {cls}, OpenGL renderer {renderer}, {img.shape[1]}x{img.shape[0]} screenshot, {red} red pixels")
want = os.environ.get("VTK_DEFAULT_OPENGL_WINDOW")
assert not want or cls == want, (cls, want)
assert red > 1000, "the sphere is not in the screenshot"
print("GL/X libraries loaded (/proc/self/maps):", *libs, sep="\n  ")
EOF
cat >"$ROOT/tmp/container-check-libs.sh" <<'EOF'
set -e
venv=$(python -c 'import sys; print(sys.prefix)')
owner() {  # the Debian package of a library path (usrmerge: try /lib, /usr/lib, the target)
  for p in "$1" "/usr$1" "$(readlink -f "$1")"; do dpkg -S "$p" 2>/dev/null && return; done; echo "?: $1"; }
sys_libs() { ldd "$@" | awk '/not found/ {print $1 " NOT-FOUND"} $3 ~ /^\// && $3 !~ "^'"$venv"'" {print $3}' | sort -u; }
for f in "$venv"/lib/libgmsh.so*; do
  echo "$f links (ldd):"
  sys_libs "$f" | while read -r l; do printf '  %-45s %s\n' "$l" "$(owner "$l" | head -1 | cut -d: -f1)"; done
done
echo "vtkmodules: $(ls "$venv"/lib/python*/site-packages/vtkmodules/*.so | wc -l) .so files; the system libraries they link:"
sys_libs "$venv"/lib/python*/site-packages/vtkmodules/*.so | sed 's/^/  /'
# Every .so in the venv: a library ldd cannot find must be one the wheels ship (a
# soname such as libmpi.so.12 or a hashed libgfortran-*.so, loaded first by its user).
# Skipped: plugins dlopened only for hardware or an MPI that is not used here:
# mpich's libfabric/UCX providers for InfiniBand, EFA, PSM2, and mpi4py's Open MPI module.
n=0; skipped=0; bad=
for f in $(find "$venv" -name '*.so' -o -name '*.so.*' | sort); do
  [ -f "$f" ] || continue
  case $f in */mpich/libfabric/*|*/mpich/ucx/*|*/mpi4py/MPI.openmpi*) skipped=$((skipped + 1)); continue ;; esac
  n=$((n + 1))
  for so in $(ldd "$f" 2>/dev/null | awk '/not found/ {print $1}'); do
    [ -n "$(find "$venv" -name "$so" -print -quit)" ] || bad="$bad  $f: $so\n"
  done
done
if [ -n "$bad" ]; then printf 'libraries found neither in the root nor in the venv:\n%b' "$bad"; exit 1; fi
echo "ldd: $n shared objects in $venv find their libraries in the root or the venv ($skipped MPI network/ABI plugins skipped)"
EOF
in_root RUN_ENV "cd '$WORKDIR' && sh /tmp/container-check-libs.sh \
  && python /tmp/container-check-render.py /tmp/container-check.png" || die "library check failed"
cp "$ROOT/tmp/container-check.png" "$ROOT.screenshot.png"
echo "screenshot: $ROOT.screenshot.png"

# --- 5. the command
[ ${#USER_CMD[@]} -eq 0 ] || CMD=("${USER_CMD[@]}")
if [ "$SMOKE" = 1 ]; then
  step "--smoke: not running ${CMD[*]}"
else
  step "${CMD[*]}  (in $WORKDIR)"
  in_root RUN_ENV "cd '$WORKDIR' && exec $(printf '%q ' "${CMD[@]}")" || die "${CMD[*]} failed"
fi
step "container-check passed"
