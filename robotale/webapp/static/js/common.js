// Shared by every page: JSON calls with the CSRF token, error display, the log picker.
"use strict";

const robotale = (() => {
  const csrf = document.querySelector('meta[name="csrf-token"]').content;
  const errorBox = document.getElementById("error");

  async function api(path, options = {}) {
    const init = { method: options.method || "GET", headers: { Accept: "application/json" } };
    if (options.body !== undefined) {
      init.headers["Content-Type"] = "application/json";
      init.body = JSON.stringify(options.body);
    }
    if (init.method !== "GET") init.headers["X-CSRFToken"] = csrf;
    const response = await fetch(path, init);
    const data = await response.json().catch(() => ({ error: response.statusText }));
    if (!response.ok) {
      const error = new Error(data.error || `${response.status} ${response.statusText}`);
      error.hint = data.hint || "";
      throw error;
    }
    return data;
  }

  function showError(error) {
    errorBox.textContent = error.hint ? `${error.message} ${error.hint}` : String(error.message || error);
    errorBox.hidden = false;
  }

  function clearError() {
    errorBox.hidden = true;
    errorBox.textContent = "";
  }

  function el(tag, attributes = {}, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes)) {
      if (key === "class") node.className = value;
      else if (key === "text") node.textContent = value;
      else node.setAttribute(key, value);
    }
    for (const child of children) node.append(child);
    return node;
  }

  function table(columns, rows) {
    const head = el("tr", {}, ...columns.map((c) => el("th", { text: c })));
    const body = rows.map((row) =>
      el("tr", {}, ...row.map((value) => {
        const text = value === null ? "null" : typeof value === "object" ? JSON.stringify(value) : String(value);
        return el("td", { class: typeof value === "number" ? "number" : "", text });
      })));
    return el("table", { class: "data" }, el("thead", {}, head), el("tbody", {}, ...body));
  }

  // The stored logs come inside the page (the server listed them anyway); else ask for them.
  let logsPromise = null;
  function logs() {
    const embedded = document.getElementById("logs-data");
    logsPromise = logsPromise || (embedded
      ? Promise.resolve(JSON.parse(embedded.textContent))
      : api("/api/logs").then((data) => data.logs));
    return logsPromise;
  }

  // The chosen log: the page's ?log=, else the last one chosen here, else the newest stored.

  async function currentLog() {
    const asked = document.body.dataset.log;
    if (asked) return asked;
    const names = (await logs()).map((log) => log.name);
    const remembered = localStorage.getItem("robotale.log");
    if (names.includes(remembered)) return remembered;
    return names.length ? names[names.length - 1] : "";
  }

  async function fillPicker() {
    const picker = document.getElementById("log-picker");
    if (!picker) return;
    let names;
    try {
      names = (await logs()).map((log) => log.name);
    } catch (error) {
      return; // the page itself reports what is wrong
    }
    const chosen = await currentLog();
    picker.replaceChildren(
      ...(names.length ? names : [""]).map((name) =>
        el("option", { value: name, text: name || "no logs yet" })));
    picker.value = chosen;
    if (chosen) localStorage.setItem("robotale.log", chosen);
    picker.addEventListener("change", () => {
      localStorage.setItem("robotale.log", picker.value);
      const url = new URL(window.location.href);
      url.search = "";
      url.searchParams.set("log", picker.value);
      window.location.assign(url);
    });
    for (const link of document.querySelectorAll("nav a[data-endpoint]")) {
      if (chosen && link.dataset.endpoint !== "logs.page") {
        link.href = `${link.pathname}?log=${encodeURIComponent(chosen)}`;
      }
    }
  }

  // Resolves once what the page `page` shows of `log` is prepared. A log nobody prepared
  // yet gets its preparation started by the first question; until the page's results are
  // ready it says how far the preparation is ("preparing … N of M"), asking again at once:
  // the dashboard answers when the preparation goes on (a step done, or the page's results
  // ready) or after two seconds, and then the page goes on to show them.
  async function prepared(log, page) {
    const asked = `/api/preparation?${new URLSearchParams({ log, page })}`;
    let status = await api(asked);
    if (status.ready) return;
    const box = document.getElementById("preparing");
    box.hidden = false;
    while (!status.ready) {
      const steps = status.total ? ` ${status.done} of ${status.total}` : "";
      const last = status.step ? ` (${status.step} done)` : "";
      box.textContent = `preparing the pages of ${log} …${steps}${last}`;
      status = await api(`${asked}&wait=2`);
    }
    box.hidden = true;
    performance.mark("robotale-prepared");
  }

  document.addEventListener("DOMContentLoaded", fillPicker);
  return { api, showError, clearError, el, table, logs, currentLog, prepared };
})();
