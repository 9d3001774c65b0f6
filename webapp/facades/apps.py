from django.apps import AppConfig


class FacadesConfig(AppConfig):
    name = "webapp.facades"
    label = "facades"
    default_auto_field = "django.db.models.BigAutoField"

    def ready(self) -> None:
        from webapp.facades import picture_store

        picture_store.connect()
