// Process graphs (DFGs and aggregated EKGs, robotale.discovery's ProcessGraph JSON) drawn with
// cytoscape.js and the layered dagre layout: zoom and pan with the mouse, edge labels,
// one colour per robot, a click on a node reports it to the page.
"use strict";

const robotaleGraph = (() => {
  cytoscape.use(cytoscapeDagre);

  // Colour-blind-safe palette (Okabe-Ito, then Tableau), assigned to robots in sorted order.
  const PALETTE = ["#0072B2", "#009E73", "#E69F00", "#CC79A7", "#56B4E9", "#D55E00",
    "#4E79A7", "#59A14F", "#B07AA1", "#9C755F", "#EDC948", "#76B7B2"];
  const SHARED = "#8a94a6"; // nodes several robots perform
  const ENTITY_EDGE = { COMM: "#D55E00", msg_id: "#D55E00" };
  // Edge types that join different robots' classes rather than follow one robot's process.
  const ACROSS = new Set(["COMM", "msg_id"]);

  function robotColours(graph) {
    const robots = new Set();
    for (const node of graph.nodes) for (const robot of node.robots || []) robots.add(robot);
    const colours = {};
    [...robots].sort().forEach((robot, i) => { colours[robot] = PALETTE[i % PALETTE.length]; });
    return colours;
  }

  function seconds(value) {
    if (value === null || value === undefined) return "-";
    if (value < 1) return `${Math.round(value * 1000)}ms`;
    if (value < 60) return `${value.toFixed(1)}s`;
    const minutes = Math.floor(value / 60);
    if (minutes < 60) return `${minutes}m${String(Math.round(value % 60)).padStart(2, "0")}s`;
    return `${Math.floor(minutes / 60)}h${String(minutes % 60).padStart(2, "0")}m`;
  }

  function nodeLabel(node, labels) {
    if (node.kind === "start" || node.kind === "end") return node.label;
    const figure = labels === "performance" ? seconds((node.durations || {}).mean) : node.count;
    // an EKG class: its instances, and its in-progress samples apart (never added to them)
    const samples = (node.properties || {}).samples;
    const extra = labels !== "performance" && samples ? ` (+${samples} samples)` : "";
    return `${node.label}\n${figure}${extra}`;
  }

  function edgeLabel(edge, labels) {
    const figure = labels === "performance" ? seconds((edge.durations || {}).mean) : edge.count;
    return edge.entity_type ? `${edge.entity_type}: ${figure}` : String(figure);
  }

  // The edges worth drawing when there are too many to read (and to lay out quickly): the
  // most frequent ones, plus each node's most frequent incoming edge so none is left alone.
  function strongestEdges(edges, limit) {
    if (!limit || edges.length <= limit) return edges;
    const byCount = [...edges].sort((a, b) => b.count - a.count);
    const kept = new Set(byCount.slice(0, limit));
    const seen = new Set();
    for (const edge of byCount) {
      if (!seen.has(edge.target)) {
        seen.add(edge.target);
        kept.add(edge);
      }
    }
    return edges.filter((edge) => kept.has(edge));
  }

  // Where a node goes in the element list: dagre breaks cycles by a depth-first search in
  // that order, so starting from the start (and entity) nodes puts them on top and makes the
  // loops (the next run's takeoff after a landing) the edges that point upwards.
  const ORDER = { start: 0, entity: 1, activity: 2, end: 3 };

  function elements(graph, colours, labels, limit) {
    const ordered = [...graph.nodes].sort((a, b) => (ORDER[a.kind] ?? 2) - (ORDER[b.kind] ?? 2));
    const nodes = ordered.map((node) => ({
      group: "nodes",
      data: {
        id: node.id,
        label: nodeLabel(node, labels),
        kind: node.kind,
        colour: node.robot ? colours[node.robot] : SHARED,
        node,
      },
    }));
    const edges = strongestEdges(graph.edges, limit).map((edge, i) => ({
      group: "edges",
      data: {
        id: `e${i}`,
        source: edge.source,
        target: edge.target,
        label: edgeLabel(edge, labels),
        colour: ENTITY_EDGE[edge.entity_type] || "#4a5568",
        width: 1 + Math.min(5, Math.log10(1 + edge.count)),
        edge,
      },
    }));
    return [...nodes, ...edges];
  }

  // Node sizes follow their labels (cytoscape's own "label" size is deprecated).
  const lines = (node) => String(node.data("label")).split("\n");
  const labelWidth = (node) => 18 + 8.4 * Math.max(...lines(node).map((line) => line.length));
  const labelHeight = (node) => 12 + 17 * lines(node).length;

  const STYLE = [
    { selector: "node", style: {
      shape: "round-rectangle", width: labelWidth, height: labelHeight,
      "background-color": "data(colour)", "background-opacity": 0.18,
      "border-width": 2, "border-color": "data(colour)",
      label: "data(label)", "text-wrap": "wrap", "text-valign": "center", "text-halign": "center",
      "font-size": 14, color: "#1d2430" } },
    { selector: "node[kind = 'start'], node[kind = 'end']", style: {
      shape: "ellipse", width: 44, height: 44, padding: 0, "background-opacity": 1,
      "background-color": "#1d2430", "border-color": "#1d2430", color: "white", "font-size": 10 } },
    { selector: "node[kind = 'entity']", style: { shape: "diamond", "font-size": 10,
      width: (node) => 1.6 * labelWidth(node), height: (node) => 1.8 * labelHeight(node) } },
    { selector: "node:selected", style: { "border-width": 4, "border-color": "#1f6feb",
      "background-opacity": 0.35 } },
    { selector: "edge", style: {
      "curve-style": "bezier", "target-arrow-shape": "triangle", width: "data(width)",
      "line-color": "data(colour)", "target-arrow-color": "data(colour)",
      label: "data(label)", "font-size": 12, color: "#364152",
      "text-background-color": "white", "text-background-opacity": 0.85,
      "text-background-padding": "2px", "text-rotation": "none" } },
    { selector: "edge.dimmed, node.dimmed", style: { opacity: 0.25 } },
  ];

  function legend(box, colours) {
    box.replaceChildren(...Object.entries(colours).map(([robot, colour]) => {
      const swatch = document.createElement("span");
      swatch.className = "swatch";
      swatch.style.background = colour;
      const item = document.createElement("span");
      item.className = "legend-item";
      item.append(swatch, robot);
      return item;
    }));
  }

  // Draws `graph` into `container`; options: labels ("frequency" | "performance"),
  // onSelect(node | null), legend (an element for the robot colours), maxEdges (draw only the
  // most frequent edges; 0: all). Returns the cytoscape instance; once the layout is done
  // `container.dataset.drawn` holds how many nodes and `container.dataset.edges` how many
  // edges were drawn.
  function draw(container, graph, options = {}) {
    const labels = options.labels || "frequency";
    const colours = robotColours(graph);
    if (options.legend) legend(options.legend, colours);
    if (container._cy) container._cy.destroy();
    delete container.dataset.drawn;
    const cy = cytoscape({
      container,
      elements: elements(graph, colours, labels, options.maxEdges),
      style: STYLE,
      minZoom: 0.05,
      maxZoom: 4,
      layout: { name: "preset" },
    });
    container._cy = cy;
    cy.on("tap", "node", (event) => {
      const node = event.target;
      cy.elements().addClass("dimmed");
      node.closedNeighborhood().removeClass("dimmed");
      if (options.onSelect) options.onSelect(node.data("node"));
    });
    cy.on("tap", (event) => {
      if (event.target !== cy) return;
      cy.elements().removeClass("dimmed");
      if (options.onSelect) options.onSelect(null);
    });
    // Ranks follow each robot's own flow (and the DFG's): message edges between robots are
    // left out of the layout, so every robot's process reads top to bottom, side by side,
    // with the messages drawn across.
    const across = cy.edges().filter((edge) => ACROSS.has(edge.data("edge").entity_type));
    const layout = cy.elements().difference(across).layout({ name: "dagre", rankDir: "TB",
      nodeSep: 30, rankSep: 45, edgeSep: 15, fit: true, padding: 15, animate: false });
    layout.one("layoutstop", () => {
      container.dataset.edges = String(cy.edges().length);
      container.dataset.drawn = String(graph.nodes.length);
      performance.mark("robotale-graph-drawn");
    });
    layout.run();
    return cy;
  }

  function zoom(container, factor) {
    const cy = container._cy;
    if (!cy) return;
    cy.zoom({ level: cy.zoom() * factor, renderedPosition: { x: cy.width() / 2, y: cy.height() / 2 } });
  }

  return { draw, zoom, seconds, robotColours };
})();
