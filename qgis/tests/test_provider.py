"""The QGIS plugin in a real, headless QGIS: every algorithm of the `skeletonise`
provider through `processing.run` (PyQGIS) and through `qgis_process`, compared
row for row with the command line's output on the training layers; the packed
ZIP (the wheel bundled) installed alone into a fresh profile (PackedPlugin).

Run by scripts/test-qgis.sh (QGIS's own Python, the wheel and the plugin on its
paths, a throw-away profile); the command line binary is $SKELETONISE_BIN, else
target/release/skeletonise, else target/debug/skeletonise.
"""

import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

from qgis.core import (
    QgsApplication,
    QgsFeature,
    QgsGeometry,
    QgsPointXY,
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingUtils,
    QgsProcessingFeedback,
    QgsVectorLayer,
)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TRAIN = os.path.join(ROOT, "tests", "data", "gshhg-train.gpkg")

sys.path.insert(0, os.path.join(ROOT, "qgis"))
from skeletonise_qgis.standalone import start  # noqa: E402

APP, PROVIDER = start()
import processing  # noqa: E402


def binary():
    for b in (os.environ.get("SKELETONISE_BIN"), "target/release/skeletonise", "target/debug/skeletonise"):
        if b and os.path.exists(os.path.join(ROOT, b) if not os.path.isabs(b) else b):
            return os.path.join(ROOT, b) if not os.path.isabs(b) else b
    raise RuntimeError("no skeletonise binary: cargo build --release")


def cli(*args, check=True):
    p = subprocess.run([binary(), *args], cwd=ROOT, capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"skeletonise {' '.join(args)} failed ({p.returncode}): {p.stderr}")
    return p


def rows(path, layer=None):
    """The features of a GeoPackage layer as {field: value} with the geometry's WKB, in FID order."""
    uri = f"{path}|layername={layer}" if layer else path
    vl = QgsVectorLayer(uri, "t", "ogr")
    assert vl.isValid(), uri
    out = []
    for f in vl.getFeatures():
        r = {name: f[name] for name in vl.fields().names() if name != "fid"}
        r = {k: (None if v is not None and hasattr(v, "isNull") and v.isNull() else v) for k, v in r.items()}
        r["_geom"] = f.geometry() if f.hasGeometry() else None
        out.append(r)
    return out


def vertices(g):
    return [(p.x(), p.y()) for p in g.vertices()]


class Case(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def out(self, name):
        return os.path.join(self.dir, name)

    def assertSameRows(self, got, want, key=("src_fid",), columns=None):  # noqa: N802
        """Row for row: the same keys (a key's rows in their order: the pieces of a
        collapsed feature), and every column of ``want`` equal (reals within 1e-9),
        geometries equal."""
        self.assertEqual(len(got), len(want))
        self.assertGreater(len(want), 0)

        def keyed(table):
            out, seen = {}, {}
            for r in table:
                k = tuple(r[c] for c in key)
                seen[k] = seen.get(k, -1) + 1
                out[k + (seen[k],)] = r
            return out

        by, want_by = keyed(got), keyed(want)
        self.assertEqual(set(by), set(want_by))
        for k, w in want_by.items():
            g = by[k]
            for c in columns or [c for c in w if c != "_geom"]:
                self.assertIn(c, g, f"column {c}")
                a, b = g[c], w[c]
                if isinstance(b, float) and a is not None:
                    self.assertTrue(math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9), f"{c}: {a} != {b} ({w[key[0]]})")
                else:
                    self.assertEqual(a, b, f"{c} of {tuple(w[k] for k in key)}")
            if w["_geom"] is None:
                self.assertIsNone(g["_geom"])
            else:
                va, vb = vertices(g["_geom"]), vertices(w["_geom"])
                self.assertEqual(len(va), len(vb))
                self.assertTrue(all(math.dist(p, q) <= 1e-6 for p, q in zip(va, vb)))


def qgis_process_program():
    # Debian's /usr/bin/qgis_process wrapper passes --noversioncheck, which qgis_process does not know.
    return "qgis_process.bin" if shutil.which("qgis_process.bin") else "qgis_process"


def fresh_environment(home):
    """A user's environment with a new, empty HOME (so a new default QGIS profile) and nothing
    of the test run's: no PYTHONPATH (the wheel the other tests use), no QGIS_PLUGINPATH."""
    env = {k: os.environ[k] for k in ("PATH", "LANG", "LC_ALL", "TMPDIR") if k in os.environ}
    env.update(HOME=home, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=home)
    return env


def gpkg_lines(path):
    """The features of a GeoPackage's one feature table with a line geometry, read with sqlite3."""
    import sqlite3

    with sqlite3.connect(path) as db:
        (table, kind), = db.execute("SELECT table_name, geometry_type_name FROM gpkg_geometry_columns").fetchall()
        count, = db.execute(f'SELECT count(*) FROM "{table}" WHERE geom IS NOT NULL').fetchone()
    return kind, count


class PackedPlugin(Case):
    """scripts/package-qgis-plugin.sh's ZIP alone, installed as Plugins ▸ Manage and Install
    Plugins ▸ Install from ZIP installs it: nothing else done."""

    @classmethod
    def setUpClass(cls):
        p = subprocess.run([os.path.join(ROOT, "scripts", "package-qgis-plugin.sh")], capture_output=True, text=True,
                           cwd=ROOT)
        assert p.returncode == 0, p.stderr
        cls.zip, cls.wheel = [os.path.join(ROOT, line) for line in p.stdout.strip().splitlines()[-2:]]

    def install(self, home):
        """The ZIP into a fresh default profile with QGIS's own installer code (pyplugin_installer's
        unzip, what Install from ZIP runs), and the plugin enabled in the profile's settings as the
        plugin manager leaves it. Returns the profile's folder."""
        import importlib.util

        spec = importlib.util.spec_from_file_location("unzip", "/usr/share/qgis/python/pyplugin_installer/unzip.py")
        installer = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(installer)
        profile = os.path.join(home, ".local", "share", "QGIS", "QGIS3", "profiles", "default")
        installer.unzip(self.zip, os.path.join(profile, "python", "plugins"))
        os.makedirs(os.path.join(profile, "QGIS"))
        with open(os.path.join(profile, "QGIS", "QGIS3.ini"), "w") as f:
            f.write("[PythonPlugins]\nskeletonise_qgis=true\n")
        return profile

    def test_the_zip_carries_the_wheel_and_what_the_plugin_repository_checks(self):
        import configparser
        import zipfile

        with zipfile.ZipFile(self.zip) as z, zipfile.ZipFile(self.wheel) as w:
            names = z.namelist()
            self.assertEqual(names[0], "skeletonise_qgis/")
            self.assertEqual({n.split("/")[0] for n in names}, {"skeletonise_qgis"})
            for n in w.namelist():
                self.assertEqual(z.read(f"skeletonise_qgis/_bundled/linux_x86_64/{n}"), w.read(n), n)
            self.assertFalse([n for n in names if ".pyc" in n or "__pycache__" in n.split("/") or ".." in n])
            self.assertIn("skeletonise_qgis/LICENSE", names)
            meta = configparser.ConfigParser(interpolation=None)
            meta.optionxform = str
            meta.read_string(z.read("skeletonise_qgis/metadata.txt").decode("utf-8"))
            general = meta["general"]
            for key in ("name", "qgisMinimumVersion", "description", "about", "version", "author", "email",
                        "homepage", "repository", "tracker", "tags", "category", "icon", "experimental",
                        "hasProcessingProvider", "changelog"):
                self.assertTrue(general.get(key, "").strip(), key)
            self.assertEqual(general["hasProcessingProvider"], "yes")
            self.assertIn(f"skeletonise_qgis/{general['icon']}", names)
            self.assertIn(general["version"], os.path.basename(self.wheel))
            self.assertIn(f"skeletonise=={general['version']}", general["about"])
        # The plugin repository takes at most 25 MB.
        self.assertLess(os.path.getsize(self.zip), 25_000_000)

    def test_install_from_zip_alone_runs_in_a_fresh_profile(self):
        home = os.path.join(self.dir, "home")
        os.makedirs(home)
        profile = self.install(home)
        env = fresh_environment(home)
        # No skeletonise in QGIS's Python of this environment but the plugin's.
        probe = subprocess.run(["/usr/bin/python3", "-c", "import skeletonise"], capture_output=True, text=True,
                               env=env, cwd=home)
        self.assertNotEqual(probe.returncode, 0)
        self.assertIn("No module named 'skeletonise'", probe.stderr)
        out = self.out("lakes.gpkg")
        run = subprocess.run(
            [qgis_process_program(), "--json", "run", "skeletonise:skeletonise",
             f"--INPUT={TRAIN}|layername=lakes_scotland", f"--OUTPUT={out}"],
            capture_output=True, text=True, env=env, cwd=home,
        )
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        result = json.loads(run.stdout[run.stdout.index("{"):])
        self.assertEqual(result["provider_details"]["long_name"], "Skeletonise 0.1.0 (bundled)")
        self.assertEqual(result["results"]["FEATURES_READ"], 18)
        self.assertEqual(result["results"]["FEATURES_REJECTED"], 0)
        self.assertEqual(gpkg_lines(out), ("MULTILINESTRING", 18))
        self.assertTrue(os.path.isfile(os.path.join(profile, "python", "plugins", "skeletonise_qgis", "_bundled",
                                                    "linux_x86_64", "skeletonise", "_core.abi3.so")))

    def test_the_bundled_copy_wins_over_an_installed_one(self):
        # An installed copy in the profile's python folder (the old way), made unloadable: the
        # bundled one is taken first and the run does not touch it.
        home = os.path.join(self.dir, "home")
        os.makedirs(home)
        profile = self.install(home)
        installed = os.path.join(profile, "python", "skeletonise")
        os.makedirs(installed)
        with open(os.path.join(installed, "__init__.py"), "w") as f:
            f.write("raise ImportError('the installed copy was imported')\n")
        run = subprocess.run(
            [qgis_process_program(), "--json", "run", "skeletonise:skeletonise",
             f"--INPUT={TRAIN}|layername=islands_hebrides", f"--OUTPUT={self.out('islands.gpkg')}"],
            capture_output=True, text=True, env=fresh_environment(home), cwd=home,
        )
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        result = json.loads(run.stdout[run.stdout.index("{"):])
        self.assertEqual(result["provider_details"]["long_name"], "Skeletonise 0.1.0 (bundled)")
        self.assertEqual(result["results"]["FEATURES_READ"], 1192)
        kind, count = gpkg_lines(self.out("islands.gpkg"))
        self.assertEqual(kind, "MULTILINESTRING")
        self.assertGreater(count, 1000)

    def test_where_no_build_is_bundled_the_algorithms_name_the_exact_install_command(self):
        home = os.path.join(self.dir, "home")
        os.makedirs(home)
        profile = self.install(home)
        plugins = os.path.join(profile, "python", "plugins")
        env = fresh_environment(home)
        script = os.path.join(ROOT, "qgis", "tests", "unsupported_platform.py")
        want = {
            ("win32", "AMD64"): ("this is Windows, not Linux",
                                 "in the OSGeo4W Shell (Start menu ▸ QGIS) run "
                                 "`python -m pip install --no-deps skeletonise==0.1.0`, then restart QGIS"),
            ("darwin", "arm64"): ("this is macOS, not Linux",
                                  "in Terminal run `{python} -m pip install --upgrade --no-deps --target "
                                  "{profile} skeletonise==0.1.0`, then restart QGIS"),
            ("linux", "aarch64"): ("this Linux runs on aarch64, not x86-64",
                                   "run `{python} -m pip install --upgrade --no-deps --target {profile} "
                                   "skeletonise==0.1.0`, then restart QGIS"),
        }
        python = f"{sys.exec_prefix}/bin/python{sys.version_info[0]}.{sys.version_info[1]}"
        for (system, machine), (reason, command) in want.items():
            with self.subTest(system=system, machine=machine):
                p = subprocess.run(
                    ["/usr/bin/python3", script, plugins, system, machine, f"{TRAIN}|layername=lakes_scotland",
                     self.out("x.gpkg")],
                    capture_output=True, text=True, env=env, cwd=home,
                )
                self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
                self.assertNotIn("Traceback", p.stdout + p.stderr)
                got = json.loads(p.stdout[p.stdout.index("{"):])
                self.assertFalse(got["on_path"])
                self.assertFalse(got["imported"])
                self.assertFalse(got["can_execute"])
                exact = command.format(python=python, profile=got["profile_python"])
                self.assertEqual(got["profile_python"], os.path.join(profile, "python"))
                for text in (got["why"], got["error"]):
                    self.assertIn("Install the skeletonise Python package 0.1.0 into QGIS's Python (the plugin "
                                  f"bundles it for x86-64 Linux only, and {reason})", text)
                    self.assertIn(exact, text)
                    self.assertNotIn("Traceback", text)
                self.assertIn("package is missing", got["long_name"])
                self.assertFalse(os.path.exists(self.out("x.gpkg")))


class Feedback(QgsProcessingFeedback):
    """Collects the errors reported and the lines of the log."""

    def __init__(self):
        super().__init__()
        self.errors = []
        self.infos = []

    def reportError(self, error, fatalError=False):  # noqa: N802
        self.errors.append(error)

    def pushInfo(self, info):  # noqa: N802
        self.infos.append(info)


def cli_refusal(*args):
    """The message of a command line that refuses its pipeline file (exit status 78)."""
    p = cli(*args, check=False)
    assert p.returncode == 78, p.stderr
    return p.stderr.strip().splitlines()[-1].split(" ERROR ", 1)[1]


def polygons_gpkg(path, layer, wkts, epsg=32630):
    """A GeoPackage layer of polygons (a `name` field) from ``(name, WKT)`` pairs, written with
    QGIS's own writer."""
    from qgis.core import QgsCoordinateTransformContext, QgsVectorFileWriter

    mem = QgsVectorLayer(f"Polygon?crs=EPSG:{epsg}&field=name:string", layer, "memory")
    features = []
    for name, wkt in wkts:
        f = QgsFeature(mem.fields())
        f["name"] = name
        f.setGeometry(QgsGeometry.fromWkt(wkt))
        features.append(f)
    mem.dataProvider().addFeatures(features)
    options = QgsVectorFileWriter.SaveVectorOptions()
    options.driverName = "GPKG"
    options.layerName = layer
    err = QgsVectorFileWriter.writeAsVectorFormatV3(mem, path, QgsCoordinateTransformContext(), options)
    assert err[0] == QgsVectorFileWriter.NoError, err
    return path


class Skeletonise(Case):
    def test_defaults_give_the_command_lines_rows_on_lakes_and_islands(self):
        for layer in ("lakes_scotland", "river_lena"):
            with self.subTest(layer=layer):
                cli("run", "-i", TRAIN, "-l", layer, "-o", self.out(f"{layer}-cli.gpkg"))
                res = processing.run(
                    "skeletonise:skeletonise",
                    {"INPUT": f"{TRAIN}|layername={layer}", "OUTPUT": self.out(f"{layer}-qgis.gpkg")},
                )
                self.assertEqual(res["FEATURES_REJECTED"], 0)
                want = rows(self.out(f"{layer}-cli.gpkg"), "skeletons")
                got = rows(res["OUTPUT"])
                self.assertTrue(all(r["rejected"] is None for r in got))
                for r in got:
                    del r["rejected"]
                self.assertSameRows(got, want)
                self.assertIn("method", want[0])

    def test_fields_named_as_the_tools_are_renamed_as_on_the_command_line(self):
        # A previous run's output as input: `src_` repeated until the name is free, as the command
        # line's writer names the fields (`src_fid` beside `src_src_fid` became `src_src_fid` twice
        # before).
        from qgis.core import QgsCoordinateTransformContext, QgsVectorFileWriter

        names = ["src_fid", "src_src_fid", "kind", "src_kind", "method"]
        spec = "&".join(f"field={n}:string" for n in names)
        mem = QgsVectorLayer(f"Polygon?crs=EPSG:32630&{spec}", "lakes", "memory")
        f = QgsFeature(mem.fields())
        for n in names:
            f[n] = n
        f.setGeometry(QgsGeometry.fromWkt("POLYGON((0 0,1000 0,1000 100,0 100,0 0))"))
        mem.dataProvider().addFeatures([f])
        path = self.out("previous.gpkg")
        options = QgsVectorFileWriter.SaveVectorOptions()
        options.driverName, options.layerName = "GPKG", "lakes"
        err = QgsVectorFileWriter.writeAsVectorFormatV3(mem, path, QgsCoordinateTransformContext(), options)
        self.assertEqual(err[0], QgsVectorFileWriter.NoError, err)
        cli("run", "-i", path, "-l", "lakes", "-o", self.out("cli.gpkg"))
        res = processing.run("skeletonise:skeletonise", {"INPUT": f"{path}|layername=lakes", "OUTPUT": self.out("q.gpkg")})
        want = rows(self.out("cli.gpkg"), "skeletons")
        got = rows(res["OUTPUT"])
        self.assertEqual([k for k in got[0] if k != "rejected"], list(want[0]))
        self.assertEqual(
            [got[0][k] for k in ("src_src_src_fid", "src_src_fid", "kind", "src_kind", "src_method")],
            ["src_fid", "src_src_fid", "kind", "src_kind", "method"],
        )
        del got[0]["rejected"]
        self.assertSameRows(got, want, key=("src_src_src_fid",))

    def test_options_and_candidates_give_the_command_lines_rows(self):
        cli(
            "run", "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("cli.gpkg"),
            "--set", "steps.skeleton.methods=[MA, CDT]", "--set", "steps.prune.mode=trunk",
            "--set", "steps.extend.mode=ray", "--set", "steps.select.by=deviation",
            "--set", "output.candidates=true",
        )
        res = processing.run(
            "skeletonise:skeletonise",
            {
                "INPUT": f"{TRAIN}|layername=lakes_scotland",
                "METHODS": [0, 3],
                "PRUNE": 2,
                "EXTEND": 1,
                "SELECT": 1,
                "OUTPUT": self.out("q.gpkg"),
                "CANDIDATES": self.out("qc.gpkg"),
            },
        )
        got = rows(res["OUTPUT"])
        for r in got:
            del r["rejected"]
        self.assertSameRows(got, rows(self.out("cli.gpkg"), "skeletons"))
        cand = rows(res["CANDIDATES"])
        self.assertSameRows(cand, rows(self.out("cli.gpkg"), "candidates"), key=("src_fid", "method"))
        self.assertEqual({r["method"] for r in cand}, {"MA", "CDT"})

    def test_qgis_process_gives_the_command_lines_rows(self):
        cli("run", "-i", TRAIN, "-l", "islands_hebrides", "-o", self.out("cli.gpkg"))
        p = subprocess.run(
            [
                os.path.join(ROOT, "scripts", "qgis-process.sh"), "--json", "run", "skeletonise:skeletonise", "--",
                f"INPUT={TRAIN}|layername=islands_hebrides", f"OUTPUT={self.out('qp.gpkg')}",
            ],
            capture_output=True, text=True, cwd=ROOT,
        )
        self.assertEqual(p.returncode, 0, p.stderr)
        result = json.loads(p.stdout[p.stdout.index("{"):])
        self.assertEqual(result["results"]["FEATURES_READ"], 1192)
        got = rows(self.out("qp.gpkg"))
        for r in got:
            del r["rejected"]
        self.assertSameRows(got, rows(self.out("cli.gpkg"), "skeletons"))

    def test_without_the_wheel_the_provider_loads_and_says_what_to_install(self):
        env = dict(os.environ, SKELETONISE_QGIS_NO_WHEEL="1")
        env.pop("PYTHONPATH", None)
        script = os.path.join(ROOT, "scripts", "qgis-process.sh")
        listed = subprocess.run([script, "list"], capture_output=True, text=True, cwd=ROOT, env=env)
        self.assertEqual(listed.returncode, 0, listed.stderr)
        self.assertIn("skeletonise:skeletonise", listed.stdout)
        run = subprocess.run(
            [script, "run", "skeletonise:skeletonise", "--", f"INPUT={TRAIN}|layername=lakes_scotland",
             f"OUTPUT={self.out('x.gpkg')}"],
            capture_output=True, text=True, cwd=ROOT, env=env,
        )
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("skeletonise Python package", run.stdout + run.stderr)
        self.assertIn("pip install --upgrade --no-deps --target", run.stdout + run.stderr)
        self.assertIn("skeletonise==0.1.0", run.stdout + run.stderr)
        self.assertNotIn("Traceback", run.stdout + run.stderr)
        self.assertFalse(os.path.exists(self.out("x.gpkg")))

    def test_an_output_onto_an_input_file_is_refused_and_the_input_kept(self):
        import hashlib

        src = self.out("lakes.gpkg")
        shutil.copy(TRAIN, src)
        before = hashlib.sha256(Path(src).read_bytes()).hexdigest()
        for alg, params in (
            ("skeletonise:skeletonise", {"INPUT": f"{src}|layername=lakes_scotland", "OUTPUT": src}),
            ("skeletonise:label", {"INPUT": f"{src}|layername=lakes_scotland", "OUTPUT": self.out("l.gpkg"), "POINTS": src}),
        ):
            with self.subTest(algorithm=alg), self.assertRaises(QgsProcessingException) as e:
                processing.run(alg, params)
            self.assertIn("choose another output file", str(e.exception))
        self.assertEqual(hashlib.sha256(Path(src).read_bytes()).hexdigest(), before)

    def test_a_geographic_layer_is_refused_with_the_reprojection_hint(self):
        lonlat = processing.run(
            "native:reprojectlayer",
            {"INPUT": f"{TRAIN}|layername=lakes_scotland", "TARGET_CRS": "EPSG:4326", "OUTPUT": "memory:"},
        )["OUTPUT"]
        with self.assertRaises(QgsProcessingException) as e:
            processing.run("skeletonise:skeletonise", {"INPUT": lonlat, "OUTPUT": self.out("x.gpkg")})
        self.assertIn("geographic CRS EPSG:4326", str(e.exception))
        self.assertIn("native:reprojectlayer", str(e.exception))
        self.assertFalse(os.path.exists(self.out("x.gpkg")))

    def test_a_feature_without_polygon_is_reported_and_kept(self):
        layer = QgsVectorLayer("Polygon?crs=EPSG:32630&field=name:string", "bad", "memory")
        good = QgsFeature(layer.fields())
        good.setAttributes(["square"])
        good.setGeometry(QgsGeometry.fromPolygonXY([[QgsPointXY(0, 0), QgsPointXY(1000, 0), QgsPointXY(1000, 200), QgsPointXY(0, 200)]]))
        empty = QgsFeature(layer.fields())
        empty.setAttributes(["nothing"])
        layer.dataProvider().addFeatures([good, empty])
        feedback = Feedback()
        res = processing.run(
            "skeletonise:skeletonise", {"INPUT": layer, "OUTPUT": self.out("r.gpkg")}, feedback=feedback
        )
        got = rows(res["OUTPUT"])
        self.assertEqual(len(got), 2)
        self.assertEqual(res["FEATURES_REJECTED"], 1)
        bad = [r for r in got if r["name"] == "nothing"][0]
        # No line (QGIS's GeoPackage writer stores a missing geometry as an empty one).
        self.assertTrue(bad["_geom"] is None or bad["_geom"].isEmpty())
        self.assertTrue(bad["rejected"])
        self.assertEqual(len(feedback.errors), 1)
        self.assertIn(bad["rejected"], feedback.errors[0])
        ok = [r for r in got if r["name"] == "square"][0]
        self.assertIsNotNone(ok["_geom"])

    def test_cancel_stops_within_a_second(self):
        # 400 rough lobed polygons of 2 000 vertices (the roughness of scripts/make_rough_polygon.py):
        # many seconds of work, each feature a small part of it (a cancel stops before the next one).
        layer = QgsVectorLayer("Polygon?crs=EPSG:3857", "rough", "memory")
        rnd = random.Random(7)
        feats = []
        for k in range(400):
            ring = []
            n = 2_000
            for i in range(n):
                t = 2 * math.pi * i / n
                r = 10_000 * (1 + 0.3 * math.sin(5 * t)) + rnd.uniform(0, 150)
                ring.append(QgsPointXY(k * 40_000 + r * math.cos(t) / 5, r * math.sin(t) / 5))
            f = QgsFeature()
            f.setGeometry(QgsGeometry.fromPolygonXY([ring]))
            feats.append(f)
        layer.dataProvider().addFeatures(feats)
        feedback = Feedback()
        cancelled = []

        def cancel():
            cancelled.append(time.monotonic())
            feedback.cancel()

        timer = threading.Timer(1.5, cancel)
        timer.start()
        t0 = time.monotonic()
        res = processing.run(
            "skeletonise:skeletonise", {"INPUT": layer, "OUTPUT": self.out("c.gpkg")}, feedback=feedback
        )
        end = time.monotonic()
        timer.cancel()
        self.assertTrue(cancelled, "the run ended before the cancel: make the layer larger")
        print(f"cancel: stopped {end - cancelled[0]:.2f} s after it", file=sys.stderr)
        self.assertLess(end - cancelled[0], 1.0, f"stopped {end - cancelled[0]:.2f} s after the cancel")
        written = len(rows(res["OUTPUT"]))
        self.assertLess(written, 400)
        self.assertGreater(end - t0, 1.5)


class Collapse(Case):
    def test_collapse_gives_the_command_lines_lines_and_areas(self):
        cli("run", os.path.join(ROOT, "pipelines", "collapse-rivers.yaml"), "-o", self.out("cli.gpkg"))
        res = processing.run(
            "skeletonise:collapse",
            {
                "INPUT": f"{TRAIN}|layername=river_lena",
                "WIDTH": 1500,
                "OUTPUT": self.out("q.gpkg"),
                "AREAS": self.out("qa.gpkg"),
            },
        )
        got = rows(res["OUTPUT"])
        for r in got:
            del r["rejected"]
        want = rows(self.out("cli.gpkg"), "skeletons")
        self.assertIn("collapsed", want[0])
        self.assertSameRows(got, want)
        areas = rows(res["AREAS"])
        want_areas = rows(self.out("cli.gpkg"), "areas")
        self.assertGreater(len(want_areas), 3)
        self.assertSameRows(areas, want_areas)

    def test_connecting_lines_give_the_command_lines_legs(self):
        network = os.path.join(ROOT, "tests", "data", "network-train.gpkg")
        yaml = self.out("net.yaml")
        with open(yaml, "w") as f:
            f.write(
                "input:\n"
                f"  source: {TRAIN}\n"
                "  layer: lakes_scotland\n"
                "  connect: { source: " + network + ", layer: lines_lakes_scotland, snap: 1 }\n"
                "steps:\n"
                "  - prepare: {}\n"
                "  - skeleton: { methods: [MA] }\n"
                "  - prune: {}\n"
                "  - extend: {}\n"
                "  - collapse: { width: 400 }\n"
                "  - score: {}\n"
                "  - select: {}\n"
                f"output: {{ path: {self.out('cli.gpkg')} }}\n"
            )
        cli("run", yaml)
        res = processing.run(
            "skeletonise:collapse",
            {
                "INPUT": f"{TRAIN}|layername=lakes_scotland",
                "WIDTH": 400,
                "CONNECT": f"{network}|layername=lines_lakes_scotland",
                "SNAP": 1,
                "OUTPUT": self.out("q.gpkg"),
                "AREAS": self.out("qa.gpkg"),
            },
        )
        got = rows(res["OUTPUT"])
        for r in got:
            del r["rejected"]
        self.assertSameRows(got, rows(self.out("cli.gpkg"), "skeletons"))
        # The lines reach the connecting lines: without them the skeletons differ.
        res = processing.run(
            "skeletonise:collapse",
            {"INPUT": f"{TRAIN}|layername=lakes_scotland", "WIDTH": 400, "OUTPUT": self.out("n.gpkg")},
        )
        plain = {r["src_fid"]: r["_geom"].length() for r in rows(res["OUTPUT"])}
        self.assertTrue(any(r["_geom"].length() > plain[r["src_fid"]] + 1 for r in got))


class Partition(Case):
    def test_partition_gives_the_command_lines_coverage_and_boundaries(self):
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        cli("run", os.path.join(ROOT, "pipelines", "partition-rivers.yaml"), "-o", self.out("cli.gpkg"))
        res = processing.run(
            "skeletonise:partition",
            {
                "INPUT": f"{cov}|layername=rivers_danube",
                "NEIGHBOURS": f"{cov}|layername=units_danube",
                "COVERAGE": self.out("c.gpkg"),
                "BOUNDARIES": self.out("b.gpkg"),
                "AREAS": self.out("a.gpkg"),
                "OUTPUT": self.out("s.gpkg"),
            },
        )
        coverage = rows(res["COVERAGE"])
        want = rows(self.out("cli.gpkg"), "coverage")
        self.assertIn("landuse", want[0])
        self.assertSameRows(coverage, want)
        self.assertGreater(sum(1 for r in coverage if r["received"] > 0), 5)
        self.assertSameRows(rows(res["BOUNDARIES"]), rows(self.out("cli.gpkg"), "boundaries"), key=("left_fid", "right_fid"))
        skel = rows(res["OUTPUT"])
        for r in skel:
            del r["rejected"]
        # The four reaches are merged into one river (members), as the command line merges them.
        self.assertSameRows(skel, rows(self.out("cli.gpkg"), "skeletons"))
        self.assertEqual(len(skel), 1)
        self.assertEqual(res["FEATURES_READ"], 4)
        # The grown coverage keeps the units' and the river's area (no gap, no overlap is the CLI's test).
        units = QgsVectorLayer(f"{cov}|layername=units_danube", "u", "ogr")
        river = QgsVectorLayer(f"{cov}|layername=rivers_danube", "r", "ogr")
        total = sum(f.geometry().area() for f in units.getFeatures()) + sum(f.geometry().area() for f in river.getFeatures())
        grown = sum(r["_geom"].area() for r in coverage) + sum(r["_geom"].area() for r in rows(res["AREAS"]))
        self.assertAlmostEqual(grown, total, delta=1e-9 * total)

    def test_units_that_cover_a_lake_are_cut_as_on_the_command_line(self):
        # Real countries covering Lake Titicaca (tests/data/border-waters.gpkg): Overlap cut (the
        # default) gives the command line's coverage; reject rejects the lake; Snap is taken.
        src = os.path.join(ROOT, "tests", "data", "border-waters.gpkg")
        pipeline = os.path.join(ROOT, "pipelines", "partition-border-waters.yaml")
        cli("run", pipeline, "-o", self.out("cli.gpkg"), "--set", "input.layer=waters_titicaca",
            "--set", "input.neighbours.layer=units_titicaca", "--set", f"input.source={src}",
            "--set", f"input.neighbours.source={src}")
        params = {
            "INPUT": f"{src}|layername=waters_titicaca",
            "NEIGHBOURS": f"{src}|layername=units_titicaca",
            "COVERAGE": self.out("c.gpkg"),
            "BOUNDARIES": self.out("b.gpkg"),
        }
        res = processing.run("skeletonise:partition", params)
        coverage = rows(res["COVERAGE"])
        self.assertSameRows(coverage, rows(self.out("cli.gpkg"), "coverage"))
        self.assertTrue(all(r["held"] > 0 for r in coverage))
        res = processing.run("skeletonise:partition", dict(params, OVERLAP=1, COVERAGE=self.out("c2.gpkg"),
                                                           BOUNDARIES=self.out("b2.gpkg")))
        self.assertGreaterEqual(res["FEATURES_REJECTED"], 1)
        res = processing.run("skeletonise:partition", dict(params, SNAP=0.01, COVERAGE=self.out("c3.gpkg"),
                                                           BOUNDARIES=self.out("b3.gpkg")))
        areas = sorted(r["_geom"].area() for r in rows(res["COVERAGE"]))
        want = sorted(r["_geom"].area() for r in coverage)
        for a, b in zip(areas, want):
            self.assertAlmostEqual(a, b, delta=1e-6 * b)

    def test_a_pipeline_with_a_label_step_renames_fields_as_the_command_line(self):
        # The `labels` layer carries the source's fields and has a `kind` column: the command line
        # writes a source field `kind` as `src_kind` in every layer, the skeletons too; so does QGIS.
        from qgis.core import QgsCoordinateTransformContext, QgsVectorFileWriter

        mem = QgsVectorLayer("Polygon?crs=EPSG:32630&field=kind:string", "lakes", "memory")
        f = QgsFeature(mem.fields())
        f["kind"] = "loch"
        f.setGeometry(QgsGeometry.fromWkt("POLYGON((0 0,4000 0,4000 400,0 400,0 0))"))
        mem.dataProvider().addFeatures([f])
        path = self.out("kind.gpkg")
        options = QgsVectorFileWriter.SaveVectorOptions()
        options.driverName, options.layerName = "GPKG", "lakes"
        err = QgsVectorFileWriter.writeAsVectorFormatV3(mem, path, QgsCoordinateTransformContext(), options)
        self.assertEqual(err[0], QgsVectorFileWriter.NoError, err)
        pipeline = os.path.join(ROOT, "pipelines", "lake-labels.yaml")
        cli("run", pipeline, "-i", path, "-l", "lakes", "-o", self.out("cli.gpkg"))
        res = processing.run(
            "skeletonise:pipeline", {"INPUT": f"{path}|layername=lakes", "PIPELINE": pipeline, "OUTPUT": self.out("q.gpkg")}
        )
        want = rows(self.out("cli.gpkg"), "skeletons")
        got = rows(res["OUTPUT"])
        self.assertEqual(want[0]["src_kind"], "loch")
        self.assertEqual([k for k in got[0] if k != "rejected"], list(want[0]))
        self.assertEqual(got[0]["src_kind"], "loch")

    def test_a_pipeline_file_with_a_partition_step_needs_the_neighbours(self):
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        with self.assertRaises(QgsProcessingException) as e:
            processing.run(
                "skeletonise:pipeline",
                {
                    "INPUT": f"{cov}|layername=rivers_danube",
                    "PIPELINE": os.path.join(ROOT, "pipelines", "partition-rivers.yaml"),
                    "OUTPUT": self.out("s.gpkg"),
                },
            )
        self.assertIn("Neighbours", str(e.exception))
        res = processing.run(
            "skeletonise:pipeline",
            {
                "INPUT": f"{cov}|layername=rivers_danube",
                "NEIGHBOURS": f"{cov}|layername=units_danube",
                "PIPELINE": os.path.join(ROOT, "pipelines", "partition-rivers.yaml"),
                "OUTPUT": self.out("s.gpkg"),
                "COVERAGE": self.out("c.gpkg"),
            },
        )
        cli("run", os.path.join(ROOT, "pipelines", "partition-rivers.yaml"), "-o", self.out("cli.gpkg"))
        self.assertSameRows(rows(res["COVERAGE"]), rows(self.out("cli.gpkg"), "coverage"))


    def test_the_log_counts_the_features_the_command_line_counts(self):
        # The summary line gives the command line's run record (read, written, rejected), with the
        # Skeletons output or without it (it is optional here), and with rejected lakes.
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        src = os.path.join(ROOT, "tests", "data", "border-waters.gpkg")
        cli("run", os.path.join(ROOT, "pipelines", "partition-rivers.yaml"), "-o", self.out("danube.gpkg"))
        titicaca = ["--set", "input.layer=waters_titicaca", "--set", "input.neighbours.layer=units_titicaca",
                    "--set", f"input.source={src}", "--set", f"input.neighbours.source={src}"]
        pipeline = os.path.join(ROOT, "pipelines", "partition-border-waters.yaml")
        cli("run", pipeline, "-o", self.out("titicaca.gpkg"), *titicaca)
        cli("run", pipeline, "-o", self.out("reject.gpkg"), *titicaca, "--set", "steps.partition.overlap=reject")
        lakes = {"INPUT": f"{src}|layername=waters_titicaca", "NEIGHBOURS": f"{src}|layername=units_titicaca"}
        cases = [
            ("danube", {"INPUT": f"{cov}|layername=rivers_danube", "NEIGHBOURS": f"{cov}|layername=units_danube"}),
            ("titicaca", lakes),
            ("reject", dict(lakes, OVERLAP=1)),
        ]
        for name, params in cases:
            run = rows(self.out(f"{name}.gpkg"), "skeletonise_runs")[0]
            want = (f"{run['features_read']} features read, {run['features_written']} written, "
                    f"{run['features_rejected']} rejected")
            if name != "reject":
                self.assertGreater(run["features_written"], 0)
            else:
                self.assertGreater(run["features_rejected"], 0)
            for skeletons in (False, True):
                with self.subTest(case=name, skeletons=skeletons):
                    sinks = {"COVERAGE": self.out(f"{name}-{skeletons}-c.gpkg"),
                             "BOUNDARIES": self.out(f"{name}-{skeletons}-b.gpkg")}
                    if skeletons:
                        sinks["OUTPUT"] = self.out(f"{name}-s.gpkg")
                    feedback = Feedback()
                    res = processing.run("skeletonise:partition", dict(params, **sinks), feedback=feedback)
                    self.assertIn(want, feedback.infos)
                    self.assertEqual(res["FEATURES_READ"], run["features_read"])
                    self.assertEqual(res["FEATURES_REJECTED"], run["features_rejected"])

    def test_an_empty_neighbours_layer_is_refused_before_any_work(self):
        # The command line refuses an empty `input.neighbours`; so do Partition into neighbours and
        # Run a pipeline file, with its words, and nothing is written.
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        empty = polygons_gpkg(self.out("empty.gpkg"), "units", [])
        self.assertEqual(QgsVectorLayer(f"{empty}|layername=units", "u", "ogr").featureCount(), 0)
        p = cli("run", os.path.join(ROOT, "pipelines", "partition-rivers.yaml"), "-o", self.out("cli.gpkg"),
                "--set", f"input.neighbours.source={empty}", "--set", "input.neighbours.layer=units", check=False)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("`input.neighbours`: layer `units` has no units", p.stderr)
        self.assertIn("give the coverage whose units take the area", p.stderr)
        memory = QgsVectorLayer("Polygon?crs=EPSG:32633", "units", "memory")
        for alg, extra in (
            ("skeletonise:partition", {}),
            ("skeletonise:pipeline", {"PIPELINE": os.path.join(ROOT, "pipelines", "partition-rivers.yaml")}),
        ):
            for units in (f"{empty}|layername=units", memory):
                with self.subTest(algorithm=alg, units=units):
                    params = dict(extra, INPUT=f"{cov}|layername=rivers_danube", NEIGHBOURS=units,
                                  COVERAGE=self.out("c.gpkg"), OUTPUT=self.out("s.gpkg"))
                    with self.assertRaises(QgsProcessingException) as e:
                        processing.run(alg, params)
                    message = str(e.exception)
                    self.assertIn("`input.neighbours`: layer `units` has no units", message)
                    self.assertIn("give the coverage whose units take the area", message)
                    self.assertFalse(os.path.exists(self.out("c.gpkg")))
                    self.assertFalse(os.path.exists(self.out("s.gpkg")))


class Score(Case):
    def test_score_by_location_and_by_key_gives_the_command_lines_rows(self):
        cli("run", "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("run.gpkg"),
            "--set", "steps.skeleton.methods=[CDT]")
        for key in (None, "src_fid"):
            with self.subTest(key=key):
                args = ["score", "--polygons", TRAIN, "--polygons-layer", "lakes_scotland",
                        "--skeletons", self.out("run.gpkg"), "--skeletons-layer", "skeletons",
                        "--label", "mine", "-o", self.out(f"cli-{key}.gpkg")]
                if key:
                    args += ["--skeleton-key", key]
                cli(*args)
                params = {
                    "INPUT": f"{TRAIN}|layername=lakes_scotland",
                    "SKELETONS": f"{self.out('run.gpkg')}|layername=skeletons",
                    "LABEL": "mine",
                    "OUTPUT": self.out(f"q-{key}.gpkg"),
                }
                if key:
                    params["SKELETON_KEY"] = key
                res = processing.run("skeletonise:score", params)
                got = rows(res["OUTPUT"])
                for r in got:
                    del r["rejected"]
                want = rows(self.out(f"cli-{key}.gpkg"), "skeletons")
                self.assertEqual({r["method"] for r in want}, {"mine"})
                self.assertSameRows(got, want)

    def test_lines_that_join_nothing_give_the_command_lines_reason(self):
        far = QgsVectorLayer("LineString?crs=EPSG:32630", "far", "memory")
        f = QgsFeature()
        f.setGeometry(QgsGeometry.fromPolylineXY([QgsPointXY(0, 0), QgsPointXY(10, 10)]))
        far.dataProvider().addFeatures([f])
        with self.assertRaises(QgsProcessingException) as e:
            processing.run(
                "skeletonise:score",
                {"INPUT": f"{TRAIN}|layername=lakes_scotland", "SKELETONS": far, "OUTPUT": self.out("s.gpkg")},
            )
        self.assertIn("no skeleton line could be joined to a polygon (1 lines inside no polygon)", str(e.exception))

    def test_a_missing_key_field_is_named_with_the_layers_fields(self):
        # As `skeletonise score`: the layer, the field and the fields it has (a Processing error, no
        # Python KeyError), before any work.
        cli("run", "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("run.gpkg"),
            "--set", "steps.skeleton.methods=[CDT]")
        base = ["score", "--polygons", TRAIN, "--polygons-layer", "lakes_scotland", "--skeletons",
                self.out("run.gpkg"), "--skeletons-layer", "skeletons", "-o", self.out("cli.gpkg")]
        params = {"INPUT": f"{TRAIN}|layername=lakes_scotland", "SKELETONS": f"{self.out('run.gpkg')}|layername=skeletons",
                  "OUTPUT": self.out("q.gpkg")}
        for what, args, keys in (
            ("skeleton", ["--skeleton-key", "nope"], {"SKELETON_KEY": "nope"}),
            ("polygon", ["--skeleton-key", "src_fid", "--polygon-key", "nope"],
             {"SKELETON_KEY": "src_fid", "POLYGON_KEY": "nope"}),
        ):
            with self.subTest(key=what):
                p = cli(*base, *args, check=False)
                self.assertNotEqual(p.returncode, 0)
                want = p.stderr.strip().splitlines()[-1].split(" ERROR ", 1)[1]
                self.assertTrue(want.startswith(f"{what} layer `"), want)
                self.assertIn("has no field `nope`; fields: kind, area_m2", want)
                with self.assertRaises(QgsProcessingException) as e:
                    processing.run("skeletonise:score", dict(params, **keys))
                self.assertEqual(str(e.exception), want)
                self.assertFalse(os.path.exists(self.out("q.gpkg")))


class Help(unittest.TestCase):
    def test_every_algorithm_explains_every_parameter(self):
        for alg in PROVIDER.algorithms():
            text = alg.shortHelpString()
            self.assertGreater(len(text), 200, alg.id())
            for p in alg.parameterDefinitions():
                name = p.description().split(" (")[0]
                with self.subTest(algorithm=alg.id(), parameter=p.name()):
                    self.assertIn(f"<b>{name}</b>", text)
                    # The dialog's tooltip: the parameter's own entry.
                    self.assertGreater(len(p.help()), 20)
        self.assertEqual(
            {a.id() for a in PROVIDER.algorithms()},
            {f"skeletonise:{n}" for n in ("skeletonise", "collapse", "partition", "score", "pipeline", "label")},
        )


class Pipeline(Case):
    def test_a_pipeline_file_with_overrides_gives_the_command_lines_rows(self):
        pipeline = os.path.join(ROOT, "pipelines", "islands.yaml")
        cli("run", pipeline, "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("cli.gpkg"),
            "--set", "steps.skeleton.methods=[MA, StSk]")
        res = processing.run(
            "skeletonise:pipeline",
            {
                "INPUT": f"{TRAIN}|layername=lakes_scotland",
                "PIPELINE": pipeline,
                "OVERRIDES": "steps.skeleton.methods=[MA, StSk]",
                "OUTPUT": self.out("q.gpkg"),
            },
        )
        got = rows(res["OUTPUT"])
        for r in got:
            del r["rejected"]
        self.assertSameRows(got, rows(self.out("cli.gpkg"), "skeletons"))

    def test_a_bad_pipeline_file_gives_the_command_lines_message(self):
        bad = self.out("bad.yaml")
        with open(bad, "w") as f:
            f.write("steps:\n  - skeleton: { methods: [MA, Nope] }\n")
        p = cli("validate", bad, check=False)
        self.assertNotEqual(p.returncode, 0)
        with self.assertRaises(QgsProcessingException) as e:
            processing.run(
                "skeletonise:pipeline",
                {"INPUT": f"{TRAIN}|layername=lakes_scotland", "PIPELINE": bad, "OUTPUT": self.out("q.gpkg")},
            )
        message = str(e.exception)
        self.assertIn("Nope", message)
        self.assertIn(message.splitlines()[0].split(": ", 1)[-1][:40], p.stderr)


    def lakes_pipeline(self, prune):
        """A pipeline file on the training lakes with the prune step ``prune``, no input.connect."""
        path = self.out("p.yaml")
        with open(path, "w") as f:
            f.write(f"input:\n  source: {TRAIN}\n  layer: lakes_scotland\nsteps:\n  - skeleton: {{ methods: [MA] }}\n"
                    f"  - prune: {prune}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\n"
                    f"output:\n  path: {self.out('o.gpkg')}\n")
        return path

    def test_network_pruning_without_lines_is_refused_with_the_command_lines_message(self):
        # The command line refuses `prune: {mode: network}` without input.connect (exit 78); the
        # algorithm refuses it without Connecting lines, with the same message, before any work,
        # rather than prune every lake with the fallback.
        path = self.lakes_pipeline("{ mode: network }")
        want = cli_refusal("validate", path)
        self.assertIn("`steps[1].prune.mode`", want)
        self.assertIn("input.connect", want)
        with self.assertRaises(QgsProcessingException) as e:
            processing.run("skeletonise:pipeline", {"INPUT": f"{TRAIN}|layername=lakes_scotland", "PIPELINE": path,
                                                    "OUTPUT": self.out("q.gpkg")})
        self.assertEqual(str(e.exception), want)
        self.assertFalse(os.path.exists(self.out("q.gpkg")))
        # Set by an override: the override is named.
        plain = self.lakes_pipeline("{}")
        want = cli_refusal("validate", plain, "--set", "steps.prune.mode=network")
        with self.assertRaises(QgsProcessingException) as e:
            processing.run("skeletonise:pipeline", {"INPUT": f"{TRAIN}|layername=lakes_scotland", "PIPELINE": plain,
                                                    "OVERRIDES": "steps.prune.mode=network", "OUTPUT": self.out("q.gpkg")})
        self.assertEqual(str(e.exception), want)
        # With the lines it runs.
        network = os.path.join(ROOT, "tests", "data", "network-train.gpkg")
        res = processing.run("skeletonise:pipeline", {"INPUT": f"{TRAIN}|layername=lakes_scotland", "PIPELINE": path,
                                                      "CONNECT": f"{network}|layername=lines_lakes_scotland", "SNAP": 1,
                                                      "OUTPUT": self.out("q.gpkg")})
        self.assertEqual(res["FEATURES_READ"], 18)

    def test_a_prune_fallback_outside_network_mode_is_refused_with_the_command_lines_message(self):
        path = self.lakes_pipeline("{ mode: significance, fallback: trunk }")
        want = cli_refusal("validate", path)
        self.assertIn("`steps[1].prune.fallback`", want)
        self.assertIn("only with `mode: network`", want)
        with self.assertRaises(QgsProcessingException) as e:
            processing.run("skeletonise:pipeline", {"INPUT": f"{TRAIN}|layername=lakes_scotland", "PIPELINE": path,
                                                    "OUTPUT": self.out("q.gpkg")})
        self.assertEqual(str(e.exception), want)


class Streets(Case):
    def test_the_streets_pipeline_writes_the_command_lines_streets_layer(self):
        # A registered step with a side input (the blocks, `streets.units`): QGIS opens the layer the
        # pipeline file names and writes the step's layer, row for row the command line's.
        path = os.path.join(ROOT, "pipelines", "streets.yaml")
        cli("run", path, "-o", self.out("cli.gpkg"))
        src = os.path.join(ROOT, "tests", "data", "streets.gpkg")
        res = processing.run("skeletonise:pipeline", {
            "INPUT": f"{src}|layername=quarter", "PIPELINE": path,
            "OUTPUT": self.out("q.gpkg"), "STEP_STREETS": self.out("s.gpkg"),
            "STEP_STREET_NODES": self.out("n.gpkg"),
        })
        got, want = rows(res["STEP_STREETS"]), rows(self.out("cli.gpkg"), "streets")
        self.assertGreater(len(want), 20)
        self.assertTrue(all(r["left_fid"] is not None and r["right_fid"] is not None for r in got))
        self.assertSameRows(got, want, key=("src_fid", "piece"))
        # The nodes the step makes after the last feature (one call for such a pipeline).
        got, want = rows(res["STEP_STREET_NODES"]), rows(self.out("cli.gpkg"), "street_nodes")
        self.assertEqual(len(want), 27)
        for r in got + want:
            r["at"] = r["_geom"].asWkt(6)
        self.assertSameRows(got, want, key=("at",))

class Labels(Case):
    def test_the_label_steps_parameters_are_its_schema(self):
        # Names, defaults, ranges and help from `skeletonise schema`: nothing copied by hand, so
        # QGIS cannot allow what the command line refuses (margin 1: the range ends below it).
        cli_schema = json.loads(cli("schema").stdout)
        options = cli_schema["$defs"]["label_options"]["properties"]
        alg = QgsApplication.processingRegistry().algorithmById("skeletonise:label")
        for key, option in options.items():
            p = alg.parameterDefinition(key.upper())
            self.assertIsNotNone(p, key)
            self.assertEqual(p.help(), option["description"])
            if key == "parts":
                self.assertEqual(p.options(), ["each", "largest"])
            else:
                self.assertEqual(p.defaultValue(), option["default"], key)
        margin = alg.parameterDefinition("MARGIN")
        self.assertLess(margin.maximum(), 1.0)
        self.assertGreater(margin.maximum(), 0.999999)
        self.assertEqual(margin.minimum(), 0.0)
        self.assertGreater(alg.parameterDefinition("MIN_PIXELS").minimum(), 0.0)
        self.assertEqual(alg.parameterDefinition("SMOOTH").maximum(), 180.0)

    def test_the_methods_are_the_schemas_in_the_default_lists_order(self):
        # Every method the command line has, none copied by hand: the default list's order first
        # (the indices saved models keep), as `skeletonise schema` says.
        defs = json.loads(cli("schema").stdout)["$defs"]
        default = defs["SkeletonParams"]["properties"]["methods"]["default"]
        every = default + [m for m in defs["MethodId"]["enum"] if m not in default]
        self.assertEqual(sorted(every), sorted(defs["MethodId"]["enum"]))
        p = QgsApplication.processingRegistry().algorithmById("skeletonise:skeletonise").parameterDefinition("METHODS")
        self.assertEqual(p.options(), every)
        self.assertEqual(p.defaultValue(), list(range(len(every))))
        # The order the plugin has always had: saved models' indices keep their methods.
        self.assertEqual(every, ["MA", "StSk", "DVD", "CDT", "VD"])

    def test_the_collapse_and_partition_parameters_are_their_steps_schema(self):
        # The built-in steps' options as the label step's: what `skeletonise schema` says, so the
        # dialog cannot offer a default or a range the command line does not have (tolerance 1:
        # the range ends below it). An option that may be unset is 0 there.
        defs = json.loads(cli("schema").stdout)["$defs"]
        renamed = {"collapse": {"min_length": "COLLAPSE_MIN_LENGTH"}, "partition": {"min_length": "PARTITION_MIN_LENGTH"}}
        for step, definition in (("collapse", "CollapseParams"), ("partition", "partition_options")):
            alg = QgsApplication.processingRegistry().algorithmById(f"skeletonise:{step}")
            for key, option in defs[definition]["properties"].items():
                p = alg.parameterDefinition(renamed[step].get(key, key.upper()))
                self.assertIsNotNone(p, (step, key))
                self.assertEqual(p.help(), option["description"], (step, key))
                self.assertIn(option["description"], alg.shortHelpString())
                if "$ref" in option:
                    values = [o["const"] for o in defs[option["$ref"].rsplit("/", 1)[-1]]["oneOf"]]
                    self.assertEqual(p.options(), values, (step, key))
                    self.assertEqual(p.options()[p.defaultValue()], option["default"], (step, key))
                elif "default" in option:
                    self.assertEqual(p.defaultValue(), option["default"] or 0.0, (step, key))
            tolerance = alg.parameterDefinition("TOLERANCE")
            self.assertEqual(tolerance.minimum(), 0.0)
            self.assertLess(tolerance.maximum(), 1.0)
            self.assertGreater(tolerance.maximum(), 0.999999)
        self.assertGreater(QgsApplication.processingRegistry().algorithmById("skeletonise:collapse")
                           .parameterDefinition("WIDTH").minimum(), 0.0)
        # The prune, extend and select modes are the schema's too (pruning to a network needs its
        # lines, which these algorithms do not take), each defaulting as the pipeline file does.
        alg = QgsApplication.processingRegistry().algorithmById("skeletonise:skeletonise")
        for name, definition, key, leave_out in (("PRUNE", "PruneParams", "mode", {"network"}),
                                                 ("EXTEND", "ExtendParams", "mode", set()),
                                                 ("SELECT", "SelectParams", "by", set())):
            option = defs[definition]["properties"][key]
            values = [o["const"] for o in defs[option["$ref"].rsplit("/", 1)[-1]]["oneOf"]]
            p = alg.parameterDefinition(name)
            self.assertEqual(p.options(), [v for v in values if v not in leave_out], name)
            self.assertEqual(p.options()[p.defaultValue()], option["default"], name)

    def test_labels_give_the_command_lines_rows_with_minzoom(self):
        cli("run", os.path.join(ROOT, "pipelines", "lake-labels.yaml"), "-o", self.out("cli.gpkg"))
        res = processing.run(
            "skeletonise:label",
            {"INPUT": f"{TRAIN}|layername=lakes_scotland", "OUTPUT": self.out("q.gpkg"), "POINTS": self.out("p.gpkg")},
        )
        lines, points = rows(res["OUTPUT"]), rows(res["POINTS"])
        self.assertEqual({r["kind"] for r in lines}, {"line"})
        self.assertEqual({r["kind"] for r in points}, {"point"})
        got = lines + points
        want = rows(self.out("cli.gpkg"), "labels")
        for r in got:
            del r["rejected"]
        self.assertIn("src_kind", want[0])
        self.assertSameRows(got, want, key=("src_fid", "polygon_part"))
        self.assertTrue(all(r["minzoom"] is not None for r in got))


    def test_a_polygon_with_a_spike_is_labelled_as_on_the_command_line(self):
        # QGIS's makeValid (GEOS MakeValid, as the command line's) makes a polygon and a line of a
        # polygon with a zero-width spike: its polygon is labelled, a point for the square and a
        # line for the strip, row for row the command line's labels layer.
        src = polygons_gpkg(self.out("spiked.gpkg"), "spiked", [
            ("square", "POLYGON((0 0,10 0,10 5,20 5,10 5,10 10,0 10,0 0))"),
            ("strip", "POLYGON((0 20,100 20,100 25,120 25,100 25,100 30,0 30,0 20))"),
        ])
        layer = QgsVectorLayer(f"{src}|layername=spiked", "s", "ogr")
        for f in layer.getFeatures():
            self.assertFalse(f.geometry().isGeosValid())
            self.assertEqual(f.geometry().makeValid().wkbType(), 7)  # GeometryCollection
        pipeline = self.out("labels.yaml")
        with open(pipeline, "w") as f:
            f.write(f"input: {{ source: {src}, layer: spiked }}\nsteps:\n  - prepare: {{ make_valid: true }}\n"
                    "  - skeleton: { methods: [MA] }\n  - label: {}\n  - prune: { mode: trunk }\n  - extend: {}\n"
                    f"  - score: {{}}\n  - select: {{}}\noutput: {{ path: {self.out('cli.gpkg')} }}\n")
        cli("run", pipeline)
        want = rows(self.out("cli.gpkg"), "labels")
        self.assertEqual([r["kind"] for r in want], ["point", "line"])
        feedback = Feedback()
        res = processing.run("skeletonise:label", {"INPUT": f"{src}|layername=spiked", "OUTPUT": self.out("q.gpkg"),
                                                   "POINTS": self.out("p.gpkg")}, feedback=feedback)
        self.assertEqual(feedback.errors, [])
        self.assertEqual(res["FEATURES_REJECTED"], 0)
        got = rows(res["OUTPUT"]) + rows(res["POINTS"])
        self.assertEqual([r["rejected"] for r in got], [None, None])
        for r in got:
            del r["rejected"]
        self.assertSameRows(got, want, key=("src_fid", "polygon_part"))


class QgisProcess(Case):
    """Every algorithm through `qgis_process` gives what it gives through processing.run
    (which the tests above compare with the command line)."""

    def qgis_process(self, algorithm, params):
        args = [os.path.join(ROOT, "scripts", "qgis-process.sh"), "--json", "run", algorithm]
        for k, v in params.items():
            # qgis_process 3.22 takes several values of an enum as one comma-separated value.
            args.append(f"--{k}={','.join(map(str, v)) if isinstance(v, list) else v}")
        p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        return json.loads(p.stdout[p.stdout.index("{"):])["results"]

    def same(self, algorithm, params, sinks):
        a = dict(params, **{k: self.out(f"qp-{k}.gpkg") for k in sinks})
        b = dict(params, **{k: self.out(f"pr-{k}.gpkg") for k in sinks})
        got = self.qgis_process(algorithm, a)
        want = processing.run(algorithm, b)
        for k in sinks:
            with self.subTest(algorithm=algorithm, sink=k):
                self.assertSameRows(rows(got[k]), rows(want[k]))

    def test_every_algorithm_through_qgis_process(self):
        lakes = f"{TRAIN}|layername=lakes_scotland"
        self.same("skeletonise:collapse", {"INPUT": f"{TRAIN}|layername=river_lena", "WIDTH": 1500, "PRUNE": 0},
                  ["OUTPUT", "AREAS"])
        cli("run", "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("run.gpkg"), "--set", "steps.skeleton.methods=[VD]")
        self.same("skeletonise:score", {"INPUT": lakes, "SKELETONS": f"{self.out('run.gpkg')}|layername=skeletons",
                                        "SKELETON_KEY": "src_fid", "LABEL": "vd"}, ["OUTPUT"])
        self.same("skeletonise:pipeline", {"INPUT": lakes, "PIPELINE": os.path.join(ROOT, "pipelines", "collapse-rivers.yaml"),
                                           "OVERRIDES": "steps.collapse.width=300"}, ["OUTPUT", "AREAS"])
        self.same("skeletonise:label", {"INPUT": lakes, "PARTS": 1, "MIN_PIXELS": 32}, ["OUTPUT", "POINTS"])
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        self.same("skeletonise:partition", {"INPUT": f"{cov}|layername=rivers_lena", "NEIGHBOURS": f"{cov}|layername=units_lena",
                                            "WIDTH": 1500}, ["COVERAGE", "BOUNDARIES", "AREAS"])
        self.same("skeletonise:skeletonise", {"INPUT": lakes, "METHODS": [0, 3], "PRUNE": 2}, ["OUTPUT", "CANDIDATES"])


class TemporaryOutputs(Case):
    def test_every_algorithm_writes_temporary_layers(self):
        # What the dialog does by default: "[Create temporary layer]" for every sink.
        cov = os.path.join(ROOT, "tests", "data", "coverage-train.gpkg")
        lakes = f"{TRAIN}|layername=lakes_scotland"
        cli("run", "-i", TRAIN, "-l", "lakes_scotland", "-o", self.out("run.gpkg"), "--set", "steps.skeleton.methods=[CDT]")
        cases = {
            "skeletonise:skeletonise": {"INPUT": lakes},
            "skeletonise:collapse": {"INPUT": lakes, "WIDTH": 400},
            "skeletonise:partition": {"INPUT": f"{cov}|layername=rivers_danube", "NEIGHBOURS": f"{cov}|layername=units_danube"},
            "skeletonise:score": {"INPUT": lakes, "SKELETONS": f"{self.out('run.gpkg')}|layername=skeletons"},
            "skeletonise:pipeline": {"INPUT": lakes, "PIPELINE": os.path.join(ROOT, "pipelines", "collapse-rivers.yaml")},
            "skeletonise:label": {"INPUT": lakes},
        }
        for alg_id, params in cases.items():
            alg = QgsApplication.processingRegistry().algorithmById(alg_id)
            for p in alg.destinationParameterDefinitions():
                params[p.name()] = "TEMPORARY_OUTPUT"
            with self.subTest(algorithm=alg_id):
                context = QgsProcessingContext()
                res = processing.run(alg_id, params, context=context)

                def layer(v):
                    return v if isinstance(v, QgsVectorLayer) else QgsProcessingUtils.mapLayerFromString(v, context)

                # (The pipeline's partition sinks stay unwritten: its file has no partition step.)
                counts = {p.name(): layer(res[p.name()]).featureCount()
                          for p in alg.destinationParameterDefinitions() if p.name() in res}
                self.assertGreater(max(counts.values()), 0, counts)


class Screenshots(Case):
    def test_the_dialog_and_a_result_are_drawn(self):
        p = subprocess.run(
            [sys.executable, os.path.join(ROOT, "qgis", "tests", "screenshots.py"), self.dir],
            capture_output=True, text=True, cwd=ROOT,
        )
        self.assertEqual(p.returncode, 0, p.stderr)
        from qgis.PyQt.QtGui import QImage

        def colours(name):
            img = QImage(self.out(name))
            self.assertFalse(img.isNull(), name)
            return img, {img.pixel(x, y) & 0xFFFFFF for x in range(0, img.width(), 3) for y in range(0, img.height(), 3)}

        dialog, seen = colours("qgis-dialog.png")
        self.assertGreaterEqual(dialog.width(), 900)
        self.assertGreater(len(seen), 20, "the dialog is blank")
        _, seen = colours("qgis-canvas.png")
        # The lochs' fill, the skeletons' red and the label lines' green are all drawn.
        for rgb in (0xA6CEE3, 0xE31A1C, 0x33A02C):
            self.assertIn(rgb, seen, f"colour {rgb:06x} not drawn")


if __name__ == "__main__":
    unittest.main(verbosity=2)
