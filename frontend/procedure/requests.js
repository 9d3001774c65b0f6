// The procedure page's calls to the server, through the site's API helper (../common/server.js: JSON sent with the
// CSRF token, patiently), and the server's picture of a tree, asked once more after the wait it names when
// rendering is throttled.
import {busy, makeApi} from "../common/server.js";

export class Throttled extends Error {
  constructor(seconds) { super(`busy: trying again in ${seconds} s`); this.seconds = seconds; }
}

/** The page's requests, each with the CSRF token `csrf`: `send` (JSON in, [response, JSON answer] out) and
 * `renderPatiently` (a tree's picture as an object URL). */
export function pageRequests(csrf) {
  const api = makeApi(csrf);

  // sent once: a busy answer is thrown as Throttled, for the page to wait out as long as the server says
  async function render(data) {
    const r = await api("/api/v1/render", {method: "POST", body: JSON.stringify(data), raw: true, tries: 1});
    if (busy(r)) {  // throttled, or every heavy slot of the process taken
      throw new Throttled(Math.max(1, Number(r.headers.get("Retry-After")) || 1));
    }
    if (!r.ok) { const e = await r.json().catch(() => ({})); throw new Error(JSON.stringify(e)); }
    return URL.createObjectURL(await r.blob());
  }

  // rendering is rate-limited per account (the server's "heavy" rate) and capped per process (a 503 when busy):
  // wait as told and try once more
  async function renderPatiently(data) {
    try {
      return await render(data);
    } catch (err) {
      if (!(err instanceof Throttled)) throw err;
      await new Promise((done) => setTimeout(done, err.seconds * 1000));
      return render(data);
    }
  }

  async function send(url, method, data) {
    const r = await api(url, {method, body: JSON.stringify(data), raw: true});
    return [r, await r.json().catch(() => ({}))];
  }

  return {send, renderPatiently};
}

// The first message of an error answer ({"detail": ...}, {"data": {"data": ...}}, {"values": [...]}), for a person
export function firstMessage(answer) {
  if (typeof answer === "string") return answer;
  for (const value of Object.values(answer && typeof answer === "object" ? answer : {})) {
    const text = firstMessage(Array.isArray(value) ? value[0] : value);
    if (text) return text;
  }
  return "";
}
