// The Compare page's figures: each batch's values, one per run, drawn by the shared plotly
// loader once the page's tables are shown (the figures come in the page, as JSON).
"use strict";

(() => {
  const figures = JSON.parse(document.getElementById("compare-figures-data").textContent);
  const boxes = document.querySelectorAll("#compare-figures .compare-figure");
  const drawn = [...boxes].map((box) => robotalePerspective.plot(box, figures[Number(box.dataset.index)]));
  Promise.all(drawn).then(() => {
    document.getElementById("compare-figures").dataset.shown = String(drawn.length);
    performance.mark("robotale-compare-figures-shown");
  }, (error) => {
    const status = document.createElement("p");
    status.className = "status error";
    status.textContent = error.message;
    document.getElementById("compare-figures").append(status);
  });
})();
