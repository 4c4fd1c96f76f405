// The Logs page: confirm deletions, and follow a background job (reading, storing) until done.
"use strict";

(() => {
  for (const form of document.querySelectorAll("form.delete-form")) {
    form.addEventListener("submit", (event) => {
      const name = form.querySelector("input[name=name]").value;
      if (!window.confirm(`Delete the log "${name}" and everything built from it?`)) event.preventDefault();
    });
  }

  const box = document.getElementById("job");
  if (!box) return;
  const stage = document.getElementById("job-stage");
  const count = document.getElementById("job-count");
  const bar = document.getElementById("job-progress");

  async function poll() {
    let job;
    try {
      job = await robotale.api(`/api/jobs/${box.dataset.job}`);
    } catch (error) {
      robotale.showError(error);
      return;
    }
    stage.textContent = job.stage;
    if (job.total) {
      bar.max = job.total;
      bar.value = job.done;
      count.textContent = `${job.done} / ${job.total}`;
    } else {
      bar.removeAttribute("value");
    }
    if (!job.finished) {
      setTimeout(poll, 400);
      return;
    }
    bar.max = 1;
    bar.value = 1;
    if (job.error) {
      const error = document.getElementById("job-error");
      error.textContent = job.error;
      error.hidden = false;
      box.dataset.state = "failed";
      return;
    }
    if (box.dataset.then === "reload") {
      window.location.reload();
      return;
    }
    document.getElementById("job-log").textContent = job.result.log;
    document.getElementById("job-events").textContent = job.result.events;
    document.getElementById("job-seconds").textContent = job.result.seconds;
    for (const [id, page] of [["findings-link", "findings"], ["discover-link", "discover"]]) {
      const link = document.getElementById(id);
      if (link) link.href = `/${page}?log=${encodeURIComponent(job.result.log)}`;
    }
    document.getElementById("job-done").hidden = false;
    localStorage.setItem("robotale.log", job.result.log);
    box.dataset.state = "done";
    if (job.result.mission && box.dataset.mission) {
      // a recording is replayed: its first run opens on the Mission page
      const query = `log=${encodeURIComponent(job.result.log)}&case=${encodeURIComponent(job.result.mission)}`;
      window.location.assign(`/mission?${query}`);
    }
  }

  poll();
})();
