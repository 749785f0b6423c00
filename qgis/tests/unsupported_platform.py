"""The packed plugin on a platform it bundles no build for, simulated: prints one JSON object
with what the provider and an algorithm say. Run by test_provider.py in QGIS's own Python
with no `skeletonise` importable (no PYTHONPATH, a fresh HOME and profile):

    python3 unsupported_platform.py PLUGINS_FOLDER SYSTEM MACHINE INPUT OUTPUT

PLUGINS_FOLDER holds the unpacked skeletonise_qgis (with its _bundled folder); SYSTEM is a
``sys.platform`` (win32, darwin, linux) and MACHINE a ``platform.machine()`` (AMD64, arm64,
aarch64), seen by the plugin's platform check only (bundle.py), not by QGIS.
"""

import json
import platform
import sys
import types

plugins, system, machine, source, output = sys.argv[1:6]
try:
    import skeletonise  # noqa: F401
except ImportError:
    pass
else:
    raise SystemExit(f"a skeletonise is importable before the plugin: {skeletonise.__file__}")

sys.path.insert(0, plugins)
from skeletonise_qgis import bundle  # noqa: E402

# The plugin's view of the platform; sys.path stays the real list (activate would change it).
bundle.sys = types.SimpleNamespace(**{k: getattr(sys, k) for k in dir(sys) if not k.startswith("__")})
bundle.sys.platform = system
bundle.platform = types.SimpleNamespace(
    machine=lambda: machine,
    system=lambda: {"win32": "Windows", "darwin": "Darwin"}.get(system, "Linux"),
    python_version=platform.python_version,
)

from qgis.core import QgsApplication, QgsProcessingException  # noqa: E402
from skeletonise_qgis.standalone import start  # noqa: E402

APP, PROVIDER = start()
import processing  # noqa: E402

alg = QgsApplication.processingRegistry().algorithmById("skeletonise:skeletonise")
can, why = alg.canExecute()
try:
    processing.run("skeletonise:skeletonise", {"INPUT": source, "OUTPUT": output})
    error = None
except QgsProcessingException as e:
    error = str(e)
print(json.dumps({
    "bundled_folder": bundle.FOLDER,
    "on_path": bundle.FOLDER in sys.path,
    "imported": "skeletonise" in sys.modules,
    "long_name": PROVIDER.longName(),
    "can_execute": can,
    "why": why,
    "error": error,
    "profile_python": bundle.profile_python(),
}))
