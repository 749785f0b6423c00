"""The provider in a standalone PyQGIS script (tests, benchmarks, batch jobs without the QGIS GUI):

    from skeletonise_qgis.standalone import start
    app, provider = start()
    import processing
    processing.run("skeletonise:skeletonise", {...})

Keep ``provider`` referenced: Processing's registry does not own a provider made in Python.
"""

import sys


def start(gui=False):
    """Starts QGIS (``gui``: with widgets, for the dialog's picture) and Processing, and registers
    the provider; returns the application and the provider."""
    from qgis.core import QgsApplication

    app = QgsApplication([], gui)
    app.initQgis()
    sys.path.append("/usr/share/qgis/python/plugins")
    from processing.core.Processing import Processing

    Processing.initialize()
    from .provider import SkeletoniseProvider

    provider = SkeletoniseProvider()
    QgsApplication.processingRegistry().addProvider(provider)
    return app, provider
