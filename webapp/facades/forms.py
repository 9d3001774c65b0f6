from django import forms

from facaid.defaults import DEFAULT_K, MAX_K
from facaid.grammar.procedure import MAX_NODES
from webapp.facades.models import Visibility


class PhotoForm(forms.Form):
    image = forms.FileField(help_text="JPEG, PNG or WebP; at most 20 MB and 40 megapixels")
    title = forms.CharField(max_length=200, required=False)
    visibility = forms.ChoiceField(choices=Visibility.choices, initial=Visibility.PRIVATE)


class VisibilityForm(forms.Form):
    visibility = forms.ChoiceField(choices=Visibility.choices)


class ProcedureVisibilityForm(VisibilityForm):
    share_photo = forms.BooleanField(required=False, label="Share its photo too, so that viewers see the overlay")


class RealSizeForm(forms.Form):
    """The facade's real width or height; its range is checked where the API's is (`PhotoSerializer`)."""

    side = forms.ChoiceField(choices=(("width", "width"), ("height", "height")), initial="width")
    metres = forms.FloatField(required=False, widget=forms.NumberInput(attrs={"step": "0.01", "class": "metres"}),
                              help_text="empty: none (a storey is taken to be 3 m tall)")


class SegmentationForm(forms.Form):
    file = forms.FileField(required=False, help_text="a segmentation JSON file, or COCO, LabelMe or CVAT XML "
                                                     "annotations (the image of the photo's size)",
                           widget=forms.ClearableFileInput(attrs={"accept": ".json,.xml,application/json,text/xml"}))
    text = forms.CharField(widget=forms.Textarea(attrs={"rows": 4}), required=False,
                           help_text="or paste the JSON (or XML) here")


class ReconstructForm(forms.Form):
    k = forms.IntegerField(min_value=1, max_value=MAX_K, initial=DEFAULT_K, help_text="candidates decoded and compared")
    seed = forms.IntegerField(min_value=0, max_value=2**31 - 1, initial=0)
    structure = forms.ChoiceField(
        choices=[("editable", "editable: floors of tiles, for the parameters"), ("exact", "exact: as drawn")],
        initial="editable", required=False,
        help_text="the procedure you get first; the other is kept as an earlier version")


class RerunForm(forms.Form):
    nodes = forms.IntegerField(min_value=1, max_value=MAX_NODES, initial=1,
                               help_text="nodes kept, breadth first: #0 to #N-1 in the tree above (click a # to pick)")
