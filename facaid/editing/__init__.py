"""The edits a person makes to a procedure: its named parameters read and set (`parameters`, over the node
instances of `instances`; a count's edit takes `floors`, `rows` and `growth`), variations (`variation`), resizing
(`resizing`); and whether an edit did what the person meant (`check`) and the parameters describe the building
(`describes`)."""
