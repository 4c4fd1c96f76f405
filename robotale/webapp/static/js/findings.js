// The Findings page: the five answers with links to their evidence, and the runs, each a link
// to its timeline and to its replay on the Mission page.
"use strict";

(() => {
  const box = document.getElementById("findings");
  const status = document.getElementById("findings-status");
  const runsBox = document.getElementById("runs");

  function evidenceLink(log, evidence) {
    const params = new URLSearchParams({ log });
    if (evidence.kind === "timeline") {
      params.set("case", evidence.case);
      return robotale.el("a", { href: `/timeline?${params}`, class: "evidence timeline-link", text: `timeline of ${evidence.label}` });
    }
    if (evidence.kind === "node") {
      params.set("activity", evidence.activity);
      if (evidence.robot) params.set("robot", evidence.robot);
      return robotale.el("a", { href: `/perspectives?${params}`, class: "evidence node-link", text: evidence.label });
    }
    return robotale.el("a", { href: "#runs", class: "evidence", text: evidence.label });
  }

  function answerSection(log, answer) {
    const list = robotale.el("ul", {}, ...answer.sentences.filter((s) => s).map((s) => robotale.el("li", { text: s })));
    const section = robotale.el("article", { class: "answer", "data-key": answer.key },
      robotale.el("h2", { text: answer.question }), list);
    if (answer.evidence.length) {
      const links = robotale.el("p", { class: "evidence-links" }, "Evidence: ");
      answer.evidence.forEach((evidence, index) => {
        if (index) links.append(" · ");
        links.append(evidenceLink(log, evidence));
      });
      section.append(links);
    }
    return section;
  }

  function runsTable(log, runs) {
    const rows = runs.map((run) => {
      const params = new URLSearchParams({ log, case: run.case });
      const link = robotale.el("a", { href: `/timeline?${params}`, text: String(run.case) });
      params.set("t", "0");
      const replay = robotale.el("a", { href: `/mission?${params}`, class: "mission-link", text: "replay" });
      return robotale.el("tr", {},
        robotale.el("td", {}, link, " · ", replay),
        robotale.el("td", { text: run.start || "" }),
        robotale.el("td", { class: "number", text: run.duration === null ? "" : run.duration.toFixed(1) }));
    });
    const head = robotale.el("tr", {}, ...["run", "start", "seconds"].map((c) => robotale.el("th", { text: c })));
    return robotale.el("table", { class: "data" }, robotale.el("thead", {}, head), robotale.el("tbody", {}, ...rows));
  }

  async function start() {
    const log = await robotale.currentLog().catch(() => "");
    if (!log) {
      status.textContent = "No log yet: upload one on the Logs page.";
      return;
    }
    // a log nobody prepared: wait for its preparation (its requests then say what is wrong)
    await robotale.prepared(log, "findings").catch(() => {});
    try {
      const asked = new URLSearchParams({ log });
      const delay = new URLSearchParams(window.location.search).get("delay");
      if (delay) asked.set("delay", delay);
      const data = await robotale.api(`/api/findings?${asked}`);
      box.replaceChildren(...data.answers.map((answer) => answerSection(log, answer)));
      document.getElementById("runs-table").replaceChildren(runsTable(log, data.runs));
      runsBox.hidden = !data.runs.length;
      status.textContent = `Log ${log}`;
      box.dataset.state = "shown";
      performance.mark("robotale-findings-shown");
    } catch (error) {
      status.textContent = "";
      box.dataset.state = "failed";
      robotale.showError(error);
    }
  }

  start();
})();
