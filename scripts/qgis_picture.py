#!/usr/bin/python3
"""Draws GeoPackage layers as QGIS draws them, with the styles stored in the files, into a PNG:
the pictures of docs/gpkg.md. Needs Debian's qgis (python3-qgis); not run by CI.

  QT_QPA_PLATFORM=offscreen scripts/qgis_picture.py out.png WIDTH HEIGHT XMIN,YMIN,XMAX,YMAX \
      out/plan.gpkg:tiles,houses,lots [diff.gpkg:lots ...]

Layers are listed top first; each named file:layer must open with a stored style.
"""
import sys

from qgis.core import (QgsApplication, QgsMapRendererParallelJob, QgsMapSettings,
                       QgsRectangle, QgsVectorLayer)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor

out, width, height, box = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
app = QgsApplication([], False)
app.initQgis()
layers = []
for spec in sys.argv[5:]:
    path, names = spec.rsplit(":", 1)
    for name in names.split(","):
        layer = QgsVectorLayer(f"{path}|layername={name}", name, "ogr")
        if not layer.isValid():
            sys.exit(f"{path}: no layer {name}")
        message, ok = layer.loadDefaultStyle()
        if not ok:
            sys.exit(f"{path}: layer {name} has no stored style ({message})")
        layers.append(layer)
settings = QgsMapSettings()
settings.setLayers(layers)
settings.setDestinationCrs(layers[0].crs())
x0, y0, x1, y1 = map(float, box.split(","))
settings.setExtent(QgsRectangle(x0, y0, x1, y1))
settings.setOutputSize(QSize(width, height))
settings.setBackgroundColor(QColor(255, 255, 255))
job = QgsMapRendererParallelJob(settings)
job.start()
job.waitForFinished()
job.renderedImage().save(out)
print("wrote", out)
