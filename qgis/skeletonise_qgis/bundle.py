"""The skeletonise wheel the plugin's ZIP carries, and what to install where it carries none.

scripts/package-qgis-plugin.sh unpacks the manylinux_2_28 abi3 wheel (x86-64 Linux, glibc
≥ 2.28, CPython ≥ 3.9) into ``_bundled/linux_x86_64/`` of the packed plugin: a native
extension cannot be imported from inside a ZIP, so the wheel's ``skeletonise`` package and
its ``.dist-info`` lie there as files. :func:`activate` puts that folder at the front of
``sys.path`` before the plugin first imports ``skeletonise``.

Which copy wins: on a platform the bundled build runs on, the bundled one (it is the
plugin's own version), even where a ``skeletonise`` is installed in QGIS's Python too (an
older wheel unpacked into the profile's python folder, a pip install); elsewhere (Windows,
macOS, another architecture, an older glibc) the installed one, and :func:`install_hint`
says exactly what to install when there is none. A ``skeletonise`` already imported before
the plugin (by another plugin or the Python console) stays: a native module cannot be
loaded twice in one process.
"""

import os
import platform
import sys

PLATFORM = "linux_x86_64"
MIN_GLIBC = (2, 28)
MIN_PYTHON = (3, 9)
HERE = os.path.dirname(os.path.abspath(__file__))
FOLDER = os.path.join(HERE, "_bundled", PLATFORM)


def plugin_version():
    """The plugin's version (``version=`` of its metadata.txt): the wheel's version to install."""
    try:
        with open(os.path.join(HERE, "metadata.txt"), encoding="utf-8") as f:
            for line in f:
                key, sep, value = line.partition("=")
                if sep and key.strip() == "version":
                    return value.strip()
    except OSError:
        pass
    return None


def glibc():
    """The C library's version as (major, minor) where it is glibc, else None (musl, not Linux)."""
    try:
        name, _, number = (os.confstr("CS_GNU_LIBC_VERSION") or "").partition(" ")
    except (AttributeError, ValueError, OSError):
        return None
    if name != "glibc":
        return None
    try:
        return tuple(int(x) for x in number.split(".")[:2])
    except ValueError:
        return None


def unsupported():
    """Why the bundled build cannot run in this Python (a short reason), or None where it can."""
    machine = platform.machine().lower()
    if not sys.platform.startswith("linux"):
        return f"this is {system_name()}, not Linux"
    if machine not in ("x86_64", "amd64") or sys.maxsize <= 2**32:
        return f"this Linux runs on {platform.machine() or 'an unknown architecture'}, not x86-64"
    libc = glibc()
    if libc is None or libc < MIN_GLIBC:
        found = "glibc " + ".".join(map(str, libc)) if libc else "no glibc"
        return f"this Linux has {found}, the bundled build needs glibc ≥ {'.'.join(map(str, MIN_GLIBC))}"
    if sys.implementation.name != "cpython" or sys.version_info[:2] < MIN_PYTHON:
        return (
            f"QGIS runs {sys.implementation.name} {platform.python_version()}, the bundled build needs "
            f"CPython ≥ {'.'.join(map(str, MIN_PYTHON))}"
        )
    return None


def system_name():
    """The operating system as users name it."""
    if sys.platform.startswith("win"):
        return "Windows"
    if sys.platform == "darwin":
        return "macOS"
    return platform.system() or sys.platform


def available():
    """Whether the plugin carries a build this Python can load."""
    return os.path.isdir(os.path.join(FOLDER, "skeletonise")) and unsupported() is None


def activate():
    """The bundled folder at the front of ``sys.path`` when it is there and runs here; returns
    whether it is (again: calling twice changes nothing)."""
    if not available():
        return False
    if FOLDER not in sys.path:
        sys.path.insert(0, FOLDER)
    return True


def install_hint():
    """What to install, and the exact command, for this platform: one sentence without a traceback."""
    version = plugin_version()
    spec = f"skeletonise=={version}" if version else "skeletonise"
    if available():
        # The bundled copy is there and runs here, yet did not load: a damaged install.
        return (
            f"the skeletonise package bundled in {FOLDER} could not be loaded: reinstall the plugin "
            "(Plugins ▸ Manage and Install Plugins ▸ Install from ZIP) and restart QGIS"
        )
    reason = unsupported()
    if reason is None:
        why = "this copy of the plugin has no bundled build"
    else:
        why = f"the plugin bundles it for x86-64 Linux only, and {reason}"
    if sys.platform.startswith("win"):
        how = f"in the OSGeo4W Shell (Start menu ▸ QGIS) run `python -m pip install --no-deps {spec}`"
    else:
        # Into the profile's python folder (on QGIS's path): no system change, and no clash with a
        # Python that refuses pip outside a virtual environment (PEP 668).
        shell = "in Terminal run" if sys.platform == "darwin" else "run"
        how = f"{shell} `{python_command()} -m pip install --upgrade --no-deps --target {quote(profile_python())} {spec}`"
    return (
        f"install the skeletonise Python package{' ' + version if version else ''} into QGIS's Python ({why}): "
        f"{how}, then restart QGIS (--no-deps keeps QGIS's own numpy; pip needs a wheel for this platform "
        "or a Rust toolchain to build one)"
    )


def quote(path):
    """A path as one shell word."""
    return f"'{path}'" if any(c in path for c in " '\"()&;$") else path


def profile_python():
    """The QGIS profile's python folder (QGIS puts it on its Python's path): the one this plugin
    is installed in (``<profile>/python/plugins/skeletonise_qgis``), else the running profile's."""
    plugins = os.path.dirname(HERE)
    if os.path.basename(plugins) == "plugins" and os.path.basename(os.path.dirname(plugins)) == "python":
        return os.path.dirname(plugins)
    try:
        from qgis.core import QgsApplication

        settings = QgsApplication.qgisSettingsDirPath()
    except ImportError:
        settings = ""
    if not settings:
        settings = os.path.join(os.path.expanduser("~"), ".local", "share", "QGIS", "QGIS3", "profiles", "default")
    return os.path.join(os.path.normpath(settings), "python")


def python_command():
    """QGIS's own Python interpreter as a shell word (sys.executable is QGIS itself inside QGIS)."""
    for candidate in (
        os.path.join(sys.exec_prefix, "bin", f"python{sys.version_info[0]}.{sys.version_info[1]}"),
        os.path.join(sys.exec_prefix, "bin", "python3"),
        os.path.join(os.path.dirname(sys.executable), "bin", "python3"),
    ):
        if os.path.isfile(candidate):
            return quote(candidate)
    return "python3"
