/** Whether an answer says the request did not run and may be sent again: throttled (429), or every heavy slot of
 * the process taken (a 503 marked `X-Facaid-Busy`; another 503, a busy database, may come after a write). */
export function busy(r) {
  return r.status === 429 || (r.status === 503 && r.headers.get("X-Facaid-Busy") !== null);
}

/** `fetch` that waits out a busy server (`busy`): tried again after its Retry-After (1 to 10 s), `tries` times in
 * all; the last answer is returned as it is. */
export async function patientFetch(url, options = {}, tries = 4) {
  for (let i = 1; ; i++) {
    const r = await fetch(url, options);
    if (!busy(r) || i >= tries) return r;
    const seconds = Math.min(10, Math.max(1, Number(r.headers.get("Retry-After")) || 1));
    await new Promise((done) => setTimeout(done, seconds * 1000));
  }
}

/** Show `url` in `img`; a picture the server could not send yet (busy: a 503 or 429 has no picture) is asked for
 * again after 1.5 s, `tries` times in all (a query parameter that the server ignores makes each a new load). */
export function patientImage(img, url, tries = 4) {
  let tried = 1;
  clearTimeout(img.retryTimer);  // a retry left from the picture this element showed before must not come back
  img.onerror = () => {
    if (tried >= tries) return;
    tried += 1;
    img.retryTimer = setTimeout(() => { img.src = `${url}${url.includes("?") ? "&" : "?"}try=${tried}`; }, 1500);
  };
  img.src = url;
}

/** The pages' calls to the site's API, each with the CSRF token `csrf`: `api(path, options)` sends `options` as
 * `fetch` would (a body not FormData is JSON), waiting out a busy server (`patientFetch`), and resolves with the JSON
 * answer, or throws an error whose message names the fields. Two options of its own: `raw: true` resolves with the
 * Response itself, whatever its status, for a caller that reads the status, the headers or a body not JSON;
 * `tries` is patientFetch's (1: sent once, a busy answer returned as it is). */
export function makeApi(csrf) {
  return async function api(path, options = {}) {
    const {raw = false, tries = 4, ...init} = options;
    const json = init.body && !(init.body instanceof FormData);
    const r = await patientFetch(path, {credentials: "same-origin", ...init,
      headers: {"X-CSRFToken": csrf, ...(json ? {"Content-Type": "application/json"} : {}), ...(init.headers || {})}},
    tries);
    if (raw) return r;
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
