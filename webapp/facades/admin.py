from django.contrib import admin

from webapp.facades.models import Job, Photo, Procedure, ProcedureVersion, Segmentation
from webapp.facades.services import versions


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
    readonly_fields = ("accuracy", "metrics", "digest")

    def save_model(self, request, obj, form, change) -> None:
        if "data" in form.changed_data or "segmentation" in form.changed_data:
            versions.remeasure(obj)  # an edit here is a version too (Procedure.save), with fresh figures
        super().save_model(request, obj, form, change)


@admin.register(ProcedureVersion)
class ProcedureVersionAdmin(admin.ModelAdmin):
    """Read only: a version is never changed or deleted but with its procedure."""

    list_display = ("procedure", "version", "kind", "accuracy", "note", "created")
    list_filter = ("kind",)
    search_fields = ("procedure__code", "procedure__title")
    raw_id_fields = ("procedure",)

    def has_add_permission(self, request) -> bool:
        return False

    def has_change_permission(self, request, obj=None) -> bool:
        return False

    def has_delete_permission(self, request, obj=None) -> bool:
        return False


@admin.register(Job)
class JobAdmin(admin.ModelAdmin):
    list_display = ("code", "kind", "owner", "status", "progress", "attempts", "created", "finished")
    list_filter = ("status", "kind")
    search_fields = ("code", "owner__username")
    raw_id_fields = ("segmentation", "result")
