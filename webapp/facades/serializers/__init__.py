"""JSON shapes of the API, a module per resource as the API's views are (callers import the one they use):
`photos`, `segmentations`, `procedures`, `versions` (a procedure's), `jobs`; `base` holds the strict fields they
share (text that is text, numbers that are not booleans or strings) and the viewer an answer is for. Segmentations
and procedures are validated by the facaid library, whose messages name the offending field or grammar node."""
