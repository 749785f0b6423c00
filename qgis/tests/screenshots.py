"""Pictures of the plugin in a real QGIS (headless, under Xvfb or Qt's offscreen platform):
the dialog of `skeletonise:skeletonise` as Processing shows it, and a result drawn by QGIS's
own map renderer (what the map canvas shows): the training lochs with their skeletons and
label lines, run through the provider.

    scripts/qgis-process.sh --python qgis/tests/screenshots.py OUT_DIR

writes OUT_DIR/qgis-dialog.png and OUT_DIR/qgis-canvas.png (README: docs/img).
"""

import os
import sys

from qgis.core import (
    QgsApplication,
    QgsLineSymbol,
    QgsMapRendererParallelJob,
    QgsMapSettings,
    QgsMarkerSymbol,
    QgsFillSymbol,
    QgsRectangle,
    QgsSingleSymbolRenderer,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TRAIN = os.path.join(ROOT, "tests", "data", "gshhg-train.gpkg")


def start():
    sys.path.insert(0, os.path.join(ROOT, "qgis"))
    from skeletonise_qgis.standalone import start as start_qgis

    return start_qgis(gui=True)


def dialog(path):
    """The algorithm's dialog, as the Processing toolbox opens it."""
    from processing.gui.AlgorithmDialog import AlgorithmDialog

    from qgis.core import QgsProject

    QgsProject.instance().addMapLayer(QgsVectorLayer(f"{TRAIN}|layername=lakes_scotland", "lochs", "ogr"))
    alg = QgsApplication.processingRegistry().createAlgorithmById("skeletonise:skeletonise")
    d = AlgorithmDialog(alg)
    d.resize(980, 720)
    d.show()
    QgsApplication.processEvents()
    # Open on the parameters, the help beside them.
    d.grab().save(path)
    d.close()


def canvas(path, out_dir):
    import processing

    lakes = QgsVectorLayer(f"{TRAIN}|layername=lakes_scotland", "lochs", "ogr")
    skel = processing.run(
        "skeletonise:skeletonise", {"INPUT": lakes, "OUTPUT": os.path.join(out_dir, "skeletons.gpkg")}
    )["OUTPUT"]
    labelled = processing.run(
        "skeletonise:label",
        {"INPUT": lakes, "OUTPUT": os.path.join(out_dir, "labels.gpkg"), "POINTS": os.path.join(out_dir, "points.gpkg")},
    )
    labels = labelled["OUTPUT"]
    skel = QgsVectorLayer(skel, "skeletons", "ogr")
    labels_l = QgsVectorLayer(labels, "labels", "ogr")
    lakes.setRenderer(
        QgsSingleSymbolRenderer(QgsFillSymbol.createSimple({"color": "166,206,227", "outline_color": "31,120,180", "outline_width": "0.3"}))
    )
    skel.setRenderer(QgsSingleSymbolRenderer(QgsLineSymbol.createSimple({"color": "227,26,28", "width": "0.4"})))
    labels_l.setRenderer(
        QgsSingleSymbolRenderer(QgsLineSymbol.createSimple({"color": "51,160,44", "width": "0.6", "line_style": "dash"}))
    )
    points = QgsVectorLayer(labelled["POINTS"], "points", "ogr")
    points.setRenderer(QgsSingleSymbolRenderer(QgsMarkerSymbol.createSimple({"color": "51,160,44", "size": "2.5"})))
    settings = QgsMapSettings()
    settings.setLayers([points, labels_l, skel, lakes])
    settings.setDestinationCrs(lakes.crs())
    # The three southernmost lochs, close enough to see the lines within them.
    south = sorted(lakes.getFeatures(), key=lambda f: f.geometry().centroid().asPoint().y())[:3]
    extent = QgsRectangle(south[0].geometry().boundingBox())
    for f in south[1:]:
        extent.combineExtentWith(f.geometry().boundingBox())
    extent.scale(1.1)
    settings.setExtent(extent)
    settings.setOutputSize(QSize(1200, 900))
    settings.setBackgroundColor(QColor(255, 255, 255))
    job = QgsMapRendererParallelJob(settings)
    job.start()
    job.waitForFinished()
    job.renderedImage().save(path)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "img")
    os.makedirs(out, exist_ok=True)
    app, provider = start()
    dialog(os.path.join(out, "qgis-dialog.png"))
    canvas(os.path.join(out, "qgis-canvas.png"), out)
    print(os.path.join(out, "qgis-dialog.png"), os.path.join(out, "qgis-canvas.png"))
