// The job page: its status, stage, progress, message and what is happening when it is late, polled once a second until it is done or failed, then a
// link to the procedure it made. A file of its own, as the site's Content-Security-Policy runs no inline script.
const box = document.getElementById("job");
async function poll() {
  const r = await fetch(`/api/v1/jobs/${box.dataset.code}/`, {credentials: "same-origin"});
  if (!r.ok) return setTimeout(poll, 3000);
  const job = await r.json();
  const status = document.getElementById("status");
  status.textContent = job.status; status.className = `status ${job.status}`;
  document.getElementById("stage").textContent = job.status === "running" ? job.stage : "";  // "done done" else
  document.getElementById("progress").value = job.progress;
  document.getElementById("message").textContent = job.message;
  document.getElementById("note").textContent = job.note;  // a late job: waiting for a worker, or one gone silent
  if (job.result) {
    const version = job.result_version > 1 ? ` (its version ${job.result_version})` : "";
    document.getElementById("result").innerHTML = `<a href="/procedures/${job.result}">Open the procedure${version}</a>`;
  }
  if (job.status === "queued" || job.status === "running") setTimeout(poll, 1000);
}
poll();
