"""Every way a procedure or a segmentation leaves or enters FaçAID: the pictures (`render`), the annotation
formats (`interchange`: COCO, LabelMe, CVAT; `annotation`: one box per element), CityEngine CGA rules (`cga`),
the relief and its 3D formats (`relief`, `mesh`, `gltf`, `ifc`, `cityjson`, with `cityjson_check`, a validator),
and `exports`, which picks one by a file's extension. Formats read the grammar and the segmentation, never the
model."""
