// The job page: its status, stage, progress, message and what is happening when it is late, polled once a second
// (followJob, ../common/server.js) until it is done or failed, then a link to the procedure it made. A file of its
// own, as the site's Content-Security-Policy runs no inline script.
import {followJob, makeApi} from "../common/server.js";

const box = document.getElementById("job");
const api = makeApi(document.querySelector("meta[name=csrf-token]").content);

function show(job) {
  const status = document.getElementById("status");
  status.textContent = job.status; status.className = `status ${job.status}`;
  document.getElementById("stage").textContent = job.status === "running" ? job.stage : "";  // "done done" else
  document.getElementById("progress").value = job.progress;
  document.getElementById("message").textContent = job.message;
  document.getElementById("note").textContent = job.note;  // a late job: waiting for a worker, or one gone silent
  document.getElementById("attempts").textContent = job.attempts;  // a worker took it (again, if one was lost)
  if (job.result) {
    const version = job.result_version > 1 ? ` (its version ${job.result_version})` : "";
    document.getElementById("result").innerHTML =
      `<a href="/procedures/${job.result}">Open the procedure${version}</a>`;
  }
}

// a poll that fails (the server still busy after its waits, or unreachable) is tried again 3 s later
async function follow() {
  try {
    await followJob(api, box.dataset.code, show);
  } catch {
    setTimeout(follow, 3000);
  }
}
follow();
