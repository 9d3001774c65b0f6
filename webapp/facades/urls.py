from django.urls import path

from webapp.facades import views

urlpatterns = [
    path("", views.home, name="home"),
    path("photos/new", views.photo_new, name="photo-new"),
    path("photos/<str:code>", views.photo, name="photo"),
    path("photos/<str:code>/edit", views.photo_editor, name="photo-editor"),
    path("photos/<str:code>/visibility", views.photo_visibility, name="photo-visibility"),
    path("photos/<str:code>/real-size", views.photo_real_size, name="photo-real-size"),
    path("photos/<str:code>/segmentation", views.photo_segmentation, name="photo-segmentation"),
    path("photos/<str:code>/reconstruct", views.photo_reconstruct, name="photo-reconstruct"),
    path("jobs/<str:code>", views.job, name="job"),
    path("procedures/<str:code>", views.procedure, name="procedure"),
    path("procedures/<str:code>/visibility", views.procedure_visibility, name="procedure-visibility"),
    path("procedures/<str:code>/fork", views.procedure_fork, name="procedure-fork"),
    path("procedures/<str:code>/rerun", views.procedure_rerun, name="procedure-rerun"),
    path("procedures/<str:code>/delete", views.procedure_delete, name="procedure-delete"),
]
