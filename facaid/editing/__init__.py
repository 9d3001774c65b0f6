"""The edits a person makes to a procedure, and whether each did what the person meant (`check`)."""
