'use strict';
// Runs one BPMN file on bpmn-engine the way FAME's controller.js (fame-ros, src/controller.js)
// drives it: an Engine named 'fame' with the Camunda moddle, a listener on activity.start and
// activity.end, each activity's new variables added to the engine's environment when it ends,
// thrown signals broadcast with engine.execution.signal, and a ROS node in the variables
// (here a stand-in that records what the model publishes and subscribes to).
//
// usage: node harness.js MODEL.bpmn [VARIABLES_JSON] [SECONDS]
// prints one JSON object: {"trace": [[event, id, name, type], ...], "variables": {...},
// "ended": bool, "error": text or null, "published": [[topic, payload], ...]}

const fs = require('fs');
const { EventEmitter } = require('events');
const { Engine } = require('bpmn-engine');

const [model, variablesJson, seconds] = process.argv.slice(2);
const source = fs.readFileSync(model, 'utf8');
const given = variablesJson ? JSON.parse(variablesJson) : {};
const limit = Number(seconds || 10) * 1000;

// the keys controller.js's addVars leaves out (the node and the run's message)
const EXCLUDED = new Set(['ros_node', 'fields', 'content', 'properties']);
const trace = [];
const published = [];
let finished = false;

function rosNode(name) {
  // what controller.js's scripts reach as environment.variables.ros_node
  return {
    name: () => name,
    namespace: () => '/' + name,
    getLogger: () => ({ info() {}, warn() {}, error() {}, debug() {} }),
    createPublisher: (type, topic) => ({ publish: (msg) => published.push([topic, msg]) }),
    createSubscription: (type, topic, options, callback) => ({ topic }),
    destroySubscription: () => {},
  };
}

const engine = new Engine({
  name: 'fame',
  source,
  moddleOptions: { camunda: require('camunda-bpmn-moddle/resources/camunda') },
});
const listener = new EventEmitter();

listener.on('activity.start', (activity) => {
  trace.push(['start', activity.id, activity.name || '', activity.type]);
});

listener.on('activity.end', (activity) => {
  trace.push(['end', activity.id, activity.name || '', activity.type]);
  // controller.js's addVars: the activity's variables the engine does not have yet
  const known = engine.environment.variables;
  for (const [key, value] of Object.entries(activity.environment.variables)) {
    if (!EXCLUDED.has(key) && !(key in known)) engine.environment.assignVariables({ [key]: value });
  }
});

engine.broker.subscribeTmp(
  'event',
  'activity.signal',
  (routingKey, message) => {
    // controller.js broadcasts a thrown signal to the engine's own catches
    engine.execution.signal(message.content.message, { ignoreSameDefinition: true });
    published.push(['/' + (message.content.name || ''), null]);
  },
  { noAck: true },
);

function report(ended, error) {
  if (finished) return;
  finished = true;
  const variables = {};
  for (const [key, value] of Object.entries(engine.environment.variables)) {
    if (EXCLUDED.has(key)) continue;
    try {
      variables[key] = JSON.parse(JSON.stringify(value));
    } catch (e) {
      variables[key] = String(value);
    }
  }
  process.stdout.write(JSON.stringify({ trace, variables, ended, error, published }) + '\n');
  process.exit(0);
}

engine.on('end', () => report(true, null));
engine.on('error', (error) => report(false, String((error && error.message) || error)));
setTimeout(() => report(false, `still running after ${limit / 1000} s`), limit).unref();

engine
  .execute({ listener, variables: { ...given, ros_node: rosNode('robot') } })
  .catch((error) => report(false, String((error && error.message) || error)));
