// The Cypher console: examples fill the editor and run; results become tables.
"use strict";

(() => {
  const query = document.getElementById("query");
  const parameters = document.getElementById("parameters");
  const status = document.getElementById("status");
  const results = document.getElementById("results");
  const examples = JSON.parse(document.getElementById("examples-data").textContent);

  const rows = (n) => `${n} row${n === 1 ? "" : "s"}`;

  async function run() {
    robotale.clearError();
    let values;
    try {
      values = JSON.parse(parameters.value || "{}");
    } catch (error) {
      robotale.showError(new Error(`The parameters are not valid JSON: ${error.message}`));
      return;
    }
    status.textContent = "running…";
    results.replaceChildren();
    try {
      const data = await robotale.api("/api/cypher", {
        method: "POST",
        body: { query: query.value, parameters: values },
      });
      status.textContent = data.results.map((r) => rows(r.total)).join(", ");
      for (const result of data.results) {
        const counted = result.complete ? rows(result.total) : `at least ${rows(result.total)}`;
        const why = result.cut === "bytes" ? " (the rest is larger than the console sends)" : "";
        const shown = result.rows.length < result.total
          ? `showing the first ${result.rows.length} of ${counted}${why}` : counted;
        results.append(
          robotale.el("pre", { class: "statement", text: result.statement }),
          robotale.el("p", { class: "count", text: shown }),
          robotale.table(result.columns, result.rows));
      }
    } catch (error) {
      status.textContent = "refused";
      robotale.showError(error);
    }
  }

  async function useExample(name) {
    const example = examples.find((e) => e.name === name);
    const log = await robotale.currentLog().catch(() => "");
    const values = Object.fromEntries(example.parameters.map((p) => [p, p === "log" ? log : null]));
    query.value = example.text;
    parameters.value = JSON.stringify(values, null, 1);
    await run();
  }

  document.getElementById("run").addEventListener("click", run);
  query.addEventListener("keydown", (event) => {
    if (event.key === "Enter" && (event.ctrlKey || event.metaKey)) run();
  });
  for (const button of document.querySelectorAll("button.example")) {
    button.addEventListener("click", () => useExample(button.dataset.name));
  }
})();
