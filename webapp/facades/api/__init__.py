"""The JSON API (``/api/v1/``): everything the pages do, a module per resource (photos, segmentations, jobs,
procedures, versions, gallery; `common` what they share; `exception_handler` the site's errors answered with their
statuses). Documented by the OpenAPI schema at ``/api/v1/schema``. Private objects of others are 404; others' public
objects are read-only (403 to change). The views parse and answer; what the site does is in
`webapp.facades.services`, a module per resource."""
