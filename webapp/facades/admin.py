from django.contrib import admin

from webapp.facades.models import Job, Photo, Procedure, Segmentation


@admin.register(Photo)
class PhotoAdmin(admin.ModelAdmin):
    list_display = ("code", "title", "owner", "width", "height", "visibility", "created")
    list_filter = ("visibility",)
    search_fields = ("title", "owner__username", "code")


@admin.register(Segmentation)
class SegmentationAdmin(admin.ModelAdmin):
    list_display = ("code", "photo", "version", "rect_count", "created")
    search_fields = ("code", "photo__title")


@admin.register(Procedure)
class ProcedureAdmin(admin.ModelAdmin):
    list_display = ("code", "title", "owner", "visibility", "accuracy", "parent", "created")
    list_filter = ("visibility",)
    search_fields = ("title", "owner__username", "code")
    raw_id_fields = ("parent", "photo", "segmentation")


@admin.register(Job)
class JobAdmin(admin.ModelAdmin):
    list_display = ("code", "kind", "owner", "status", "progress", "attempts", "created", "finished")
    list_filter = ("status", "kind")
    search_fields = ("code", "owner__username")
    raw_id_fields = ("segmentation", "result")
