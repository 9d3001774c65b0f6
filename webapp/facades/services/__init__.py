"""What the site does, for the API's views and the pages alike, a module per resource (callers import the one they
use):

- `photos`: stored from an upload within the owner's quota, deleted with their files, rectified, corners proposed;
- `segmentations`: versions read from our JSON or another tool's file, the editor's draft, a version as a file,
  proposals for what is not drawn yet;
- `jobs`: a reconstruction's life, submitted under its owner's cap, claimed, beating, finished, recovered (sent to
  the worker by name: `webapp.facades.queue`);
- `procedures`: stored, forked, re-run;
- `versions`: a procedure's trees saved and re-measured, edited, reverted, compared, saved as a new procedure;
- `sharing`: a procedure and its photo shared, and what viewers see of them;
- `gallery`: the public gallery's pages, cached while no procedure changes;
- `files`: what they share of the stored files.

What they raise is in the site's own words (`webapp.facades.errors`: `Invalid`, `NotFound`, `NotAllowed`,
`TooManyJobs`, `QuotaError`), which the API answers with their statuses (`webapp.facades.api.exception_handler`) and
the pages show.
"""
