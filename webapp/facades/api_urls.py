from django.urls import path

from webapp.facades import api

urlpatterns = [
    path("photos/", api.photos, name="api-photos"),
    path("photos/<str:code>/", api.photo_detail, name="api-photo"),
    path("photos/<str:code>/image", api.photo_image, name="api-photo-image"),
    path("photos/<str:code>/rectify", api.photo_rectify, name="api-photo-rectify"),
    path("photos/<str:code>/corners/propose", api.photo_propose_corners, name="api-photo-propose-corners"),
    path("photos/<str:code>/segmentations/", api.photo_segmentations, name="api-photo-segmentations"),
    path("photos/<str:code>/segmentation", api.photo_segmentation_file, name="api-photo-segmentation-file"),
    path("photos/<str:code>/draft", api.photo_draft, name="api-photo-draft"),
    path("photos/<str:code>/complete", api.photo_complete, name="api-photo-complete"),
    path("segmentations/<str:code>/", api.segmentation_detail, name="api-segmentation"),
    path("jobs/", api.job_list, name="api-jobs"),
    path("jobs/<str:code>/", api.job_detail, name="api-job"),
    path("procedures/", api.procedure_list, name="api-procedures"),
    path("procedures/<str:code>/", api.procedure_detail, name="api-procedure"),
    path("procedures/<str:code>/fork", api.procedure_fork, name="api-procedure-fork"),
    path("procedures/<str:code>/variations", api.procedure_variations, name="api-procedure-variations"),
    path("procedures/<str:code>/rerun", api.procedure_rerun, name="api-procedure-rerun"),
    path("procedures/<str:code>/download/<str:name>", api.procedure_download, name="api-procedure-download"),
    path("procedures/<str:code>/thumbnail.png", api.procedure_thumbnail, name="api-procedure-thumbnail"),
    path("gallery/", api.gallery, name="api-gallery"),
    path("render", api.render_preview, name="api-render"),
    path("convert", api.convert, name="api-convert"),
]
