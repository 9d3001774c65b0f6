// The editor's calls to the site's API: JSON in and out, errors as messages that name the field.
export function makeApi(csrf) {
  return async function api(path, options = {}) {
    const json = options.body && !(options.body instanceof FormData);
    const r = await fetch(path, {credentials: "same-origin", ...options,
      headers: {"X-CSRFToken": csrf, ...(json ? {"Content-Type": "application/json"} : {}), ...(options.headers || {})}});
    const body = r.headers.get("Content-Type")?.includes("json") ? await r.json() : null;
    if (!r.ok) throw new Error(body ? Object.entries(body).map(([k, v]) => `${k}: ${v}`).join("; ") : r.statusText);
    return body;
  };
}

/** Follow a job until it ends: `update(job)` after every poll; resolves with the last job. */
export async function followJob(api, code, update, every = 1000) {
  for (;;) {
    const job = await api(`/api/v1/jobs/${code}/`);
    update(job);
    if (job.status !== "queued" && job.status !== "running") return job;
    await new Promise((resolve) => setTimeout(resolve, every));
  }
}

/** A JSON value offered as a file download. */
export function download(value, name) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([JSON.stringify(value, null, 1)], {type: "application/json"}));
  a.download = name;
  a.click();
  URL.revokeObjectURL(a.href);
}
