// The API helpers wait out a busy server: a 429 or a 503 is tried again after its Retry-After, a few times; makeApi
// sends JSON with the CSRF token and answers JSON, or, asked for it, the Response itself.
import assert from "node:assert/strict";
import {test} from "node:test";

import {makeApi, patientFetch} from "../common/server.js";

function answers(...statuses) {  // a stand-in for the network: the statuses in turn, each with Retry-After 1
  const asked = [];
  globalThis.fetch = async (url) => {
    asked.push(url);
    const status = statuses[Math.min(asked.length, statuses.length) - 1];
    const headers = {"Retry-After": "1", ...(status === 503 ? {"X-Facaid-Busy": "slots"} : {})};
    return {status, ok: status < 400, headers: {get: (name) => headers[name] ?? null}};
  };
  return asked;
}

test("a busy answer is tried again after its Retry-After, and the first other answer is returned", async () => {
  const asked = answers(503, 429, 200);
  const started = Date.now();
  const r = await patientFetch("/api/v1/render", {}, 4);
  assert.equal(r.status, 200);
  assert.equal(asked.length, 3);
  assert.ok(Date.now() - started >= 1900);  // waited about a second each time
});

test("it gives up after its tries and returns the last answer as it is", async () => {
  const asked = answers(503);
  const r = await patientFetch("/api/v1/render", {}, 2);
  assert.equal(r.status, 503);
  assert.equal(asked.length, 2);
  const other = answers(400);
  assert.equal((await patientFetch("/x")).status, 400);
  assert.equal(other.length, 1);  // other errors are not tried again
});

test("a 503 without the busy mark (a busy database, after a write perhaps) is not sent again", async () => {
  const asked = [];
  globalThis.fetch = async (url) => {
    asked.push(url);
    return {status: 503, ok: false, headers: {get: (name) => (name === "Retry-After" ? "5" : null)}};
  };
  assert.equal((await patientFetch("/api/v1/procedures/x/", {method: "PATCH"})).status, 503);
  assert.equal(asked.length, 1);
});

function answering(status, body, {busyMark = false} = {}) {  // one answer, always; what was sent, in `sent`
  const sent = [];
  globalThis.fetch = async (url, options) => {
    sent.push({url, options});
    const headers = {"Content-Type": "application/json", "Retry-After": "1",
      ...(busyMark ? {"X-Facaid-Busy": "1"} : {})};
    return {status, ok: status < 400, statusText: "Bad Request", headers: {get: (name) => headers[name] ?? null},
      json: async () => body};
  };
  return sent;
}

test("api sends JSON with the CSRF token and the cookies, answers JSON, or throws naming the fields", async () => {
  const sent = answering(200, {version: 2});
  const api = makeApi("token");
  assert.deepEqual(await api("/api/v1/x/", {method: "PATCH", body: JSON.stringify({a: 1})}), {version: 2});
  const {options} = sent[0];
  assert.equal(options.method, "PATCH");
  assert.equal(options.credentials, "same-origin");
  assert.deepEqual(options.headers, {"X-CSRFToken": "token", "Content-Type": "application/json"});
  answering(400, {data: "not a tree", values: "unknown"});
  await assert.rejects(api("/api/v1/x/", {method: "POST", body: "{}"}), {message: "data: not a tree; values: unknown"});
});

test("raw: true answers the Response itself, whatever its status, and sends no option of the api's to fetch",
  async () => {
    const sent = answering(400, {data: "not a tree"});
    const api = makeApi("token");
    const r = await api("/api/v1/x/", {method: "POST", body: "{}", raw: true});
    assert.equal(r.status, 400);
    assert.deepEqual(await r.json(), {data: "not a tree"});  // unread: the caller's to read
    assert.ok(!("raw" in sent[0].options) && !("tries" in sent[0].options));
    answering(200, {});
    assert.equal((await api("/api/v1/x/", {raw: true})).status, 200);
  });

test("tries is patientFetch's: a busy answer is sent again that many times in all, 1: sent once", async () => {
  const api = makeApi("token");
  let sent = answering(429, {detail: "throttled"});
  const r = await api("/api/v1/render", {method: "POST", body: "{}", raw: true, tries: 1});
  assert.equal(r.status, 429);
  assert.equal(sent.length, 1);
  sent = answering(503, {detail: "busy"}, {busyMark: true});
  await assert.rejects(api("/api/v1/render", {tries: 2}), {message: "detail: busy"});
  assert.equal(sent.length, 2);  // once more, after its Retry-After
});
