// The API helpers wait out a busy server: a 429 or a 503 is tried again after its Retry-After, a few times.
import assert from "node:assert/strict";
import {test} from "node:test";

import {patientFetch} from "../common/server.js";

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
