#!/usr/bin/env bash
# Builds the Python package's wheel for any Linux with CPython ≥ 3.9 into target/wheels:
# abi3, linked by zig against glibc 2.28's symbols (`maturin build --zig --compatibility
# manylinux_2_28`), so it installs on glibc ≥ 2.28 whatever glibc this machine has. Then
# `auditwheel show` checks it: the script fails unless the wheel is cp39-abi3, its tag is
# manylinux_2_28 or older and auditwheel finds it consistent with such a tag (no library
# outside the manylinux policy, no newer glibc symbol).
#   scripts/build-wheel.sh                              # release profile
#   SKELETONISE_WHEEL_PROFILE=dev scripts/build-wheel.sh  # cargo's dev profile: the same tag
# Uses the venv target/py-venv (made by `scripts/python-env.sh --no-wheel` when missing) and
# installs ziglang and auditwheel there when missing. Compiles in target/zig, a cargo target
# directory of its own: zig's linker and C compiler and maturin's explicit --target share
# nothing with target/debug or target/release. Only a wheel that passed replaces
# target/wheels/skeletonise-*.whl; the last line printed is its path.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
wheel=
fail() {
  echo "build-wheel.sh: ${wheel:+$wheel: }$1" >&2
  exit 1
}
# The newest glibc that a manylinux_X_Y tag needs, as X Y; nothing for any other tag.
glibc_of() { printf '%s\n' "$1" | sed -n 's/^manylinux_\([0-9][0-9]*\)_\([0-9][0-9]*\)_.*/\1 \2/p'; }
# Whether manylinux tag $1 needs at most the glibc of manylinux tag $2 (default 2.28).
not_newer() {
  local x y a b
  read -r x y <<<"$(glibc_of "$1")"
  read -r a b <<<"$(glibc_of "${2:-manylinux_2_28_}")"
  [ -n "$x" ] && [ -n "$a" ] && { [ "$x" -lt "$a" ] || { [ "$x" -eq "$a" ] && [ "$y" -le "$b" ]; }; }
}
[ -x "$venv/bin/python" ] || scripts/python-env.sh --no-wheel
# One run at a time (two scripts' python-env.sh at once would write the same wheel file).
mkdir -p target/zig
exec 9>target/zig/build-wheel.lock
flock 9
need=()
[ -x "$venv/bin/maturin" ] || need+=(maturin)
# ziglang 0.17.1 is the one tried with maturin 1.16; a new zig has broken such builds before.
"$venv/bin/python" -c 'import ziglang' 2>/dev/null || need+=("ziglang<0.18")
[ -x "$venv/bin/auditwheel" ] || need+=(auditwheel)
if [ ${#need[@]} -gt 0 ]; then
  "$venv/bin/python" -m pip install -q "${need[@]}"
fi
profile=${SKELETONISE_WHEEL_PROFILE:-release}
# Built and checked in target/zig/wheels, then moved to target/wheels.
out=target/zig/wheels
mkdir -p "$out"
rm -f "$out"/skeletonise-*.whl
# maturin finds `python -m ziglang` through the venv's python on PATH.
PATH="$PWD/$venv/bin:$PATH" CARGO_TARGET_DIR="$PWD/target/zig" \
  "$venv/bin/maturin" build --zig --compatibility manylinux_2_28 --profile "$profile" --quiet \
  -m python/Cargo.toml -i "$venv/bin/python" -o "$out"
wheels=("$out"/skeletonise-*.whl)
if [ ${#wheels[@]} -ne 1 ] || [ ! -f "${wheels[0]}" ]; then
  fail "expected one wheel in $out, found: ${wheels[*]}"
fi
wheel=${wheels[0]}
show=$("$venv/bin/auditwheel" show "$wheel") || fail "auditwheel show failed"
echo "$show"
# auditwheel wraps its sentences: join the lines before reading the tag.
audited=$(printf '%s\n' "$show" | tr -s ' \n' '  ' \
  | sed -n 's/.*consistent with the following platform tag: "\([^"]*\)".*/\1/p')
name=$(basename "$wheel" .whl)
platform=${name##*-}
case "$name" in
  *-cp39-abi3-*) ;;
  *) fail "not a cp39-abi3 wheel" ;;
esac
not_newer "$platform" || fail "tagged $platform, not manylinux_2_28 or older"
[ -n "$audited" ] || fail "auditwheel show named no platform tag (output above)"
# The wheel's own tag (the first, when maturin writes several) must be one auditwheel confirms.
not_newer "$audited" "${platform%%.*}" ||
  fail "tagged $platform, but auditwheel show finds it consistent only with $audited (see above)"
mkdir -p target/wheels
rm -f target/wheels/skeletonise-*.whl
mv "$wheel" target/wheels/
echo "build-wheel.sh: $platform, auditwheel: consistent with $audited (profile $profile)" >&2
echo "target/wheels/$name.whl"
