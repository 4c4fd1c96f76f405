// The runtime every robot's JavaScript context starts with (robotale/fame_runtime/javascript.py
// evaluates it after rclnodejs.js): the process variables as `environment.variables`, `next`,
// `console`, and the outbox through which what a script did goes back to Python. Every
// function is named fame_* so that an error's stack can be cut down to the script's own lines.
var __fame = (function () {
  var out = [], dirty = {}, order = [], store = {}, subs = {}, calls = {};
  // the run being called and whether it called next(null, value) meanwhile: the usual
  // completion travels as the outbox's first field instead of an effect
  var current = 0, settledNow = false, valueNow;
  var hidden = {node: true, ros_node: true};
  var variables = new Proxy(store, {
    get: function fame_get(t, k) {
      var v = t[k];
      // an object read may be changed in place (points.shift()): copy it back too
      if (typeof k === 'string' && v !== null && typeof v === 'object' && !hidden[k]) fame_dirty(k);
      return v;
    },
    set: function fame_set(t, k, v) {
      t[k] = v;
      if (dirty[k] !== 1 && !hidden[k]) { dirty[k] = 1; order.push(k); }
      return true;
    },
    deleteProperty: function fame_delete(t, k) { delete t[k]; fame_dirty(k); return true; }
  });
  function fame_dirty(k) {
    if (dirty[k] !== 1) { dirty[k] = 1; order.push(k); }
  }
  var environment = {variables: variables, services: {}, output: {}, settings: {}};
  var context = {environment: environment};
  function fame_text(args) {
    return Array.prototype.map.call(args, function fame_one(a) {
      return typeof a === 'string' ? a : JSON.stringify(a);
    }).join(' ');
  }
  function fame_log() { fame_settle(); out.push(['log', fame_text(arguments)]); }
  var console = {log: fame_log, info: fame_log, warn: fame_log, error: fame_log, debug: fame_log};
  function fame_effect(e) {  // a run's effect, after its next() if it called it meanwhile
    fame_settle();
    out.push(e);
  }
  var fame_node = fame_rclnodejs(fame_effect, subs, calls, console);
  function fame_hide(name, value) {
    Object.defineProperty(store, name, {value: value, enumerable: false, writable: true});
  }
  function fame_absorb(push) {
    if (!push) return;
    var p = JSON.parse(push), k;
    for (k in p.set) store[k] = p.set[k];
    for (var i = 0; i < p.del.length; i++) delete store[p.del[i]];
  }
  // The usual outcome of a call -- variables set to numbers, booleans, null or strings, and
  // next() -- goes back as flat text: 'C', then triples of fields separated by \x1f (w name
  // value | d name '' | n run value). JSON.stringify costs more than such a script itself.
  // Anything else goes as the JSON of an object.
  // a number JSON writes without fraction or exponent (read back as an int) is 'i'
  function fame_flat(v) {
    var t = typeof v;
    if (t === 'number') {
      if ((v | 0) === v) return 'i' + v;  // the usual: a 32-bit integer, found without a call
      if (!isFinite(v)) return null;
      return (Number.isInteger(v) && v < 1e21 && v > -1e21 ? 'i' : 'n') + v;
    }
    if (t === 'boolean') return v ? 't' : 'f';
    if (v === null || v === undefined) return 'z';
    if (t === 'string' && fame_plain(v)) return 's' + v;
    return null;
  }
  function fame_plain(text) {
    return text.indexOf('\u001f') < 0;
  }
  // The most usual outcome of all -- no effect but next(null, value) of the run called, and
  // variables set to flat values -- is 'F<value>' then pairs (name, value).
  function fame_fast(head) {
    var flat = 'F' + head, k, f, i;
    for (i = 0; i < order.length; i++) {
      k = order[i];
      f = store[k] === undefined ? null : fame_flat(store[k]);
      if (f === null || !fame_plain(k)) return '';
      flat += '\u001f' + k + '\u001f' + f;
    }
    if (flat.length > 256) flat = flat.split('\u001f').join('\u001f');  // see fame_drain
    if (i) { dirty = {}; order = []; }
    settledNow = false;
    return flat;
  }
  function fame_drain() {
    if (out.length === 0) {
      var head = settledNow ? fame_flat(valueNow) : '';
      if (head !== null) {
        if (order.length === 0) { settledNow = false; return 'F' + head; }
        var fast = fame_fast(head);
        if (fast) return fast;
      }
    }
    fame_settle();
    var flat = 'C', k, f, i, e = out;
    for (k in dirty) {
      f = store[k] === undefined ? '' : fame_flat(store[k]);
      if (f === null || !fame_plain(k)) { flat = ''; break; }
      flat += f ? '\u001fw\u001f' + k + '\u001f' + f : '\u001fd\u001f' + k + '\u001f';
    }
    for (i = 0; flat && i < e.length; i++) {
      f = e[i][0] === 'next' && e[i][2] === null ? fame_flat(e[i][3]) : null;
      flat = f === null ? '' : flat + '\u001fn\u001f' + e[i][1] + '\u001f' + f;
    }
    if (flat === 'C') return '';  // nothing written, nothing done
    // a long string built by += may be a rope, which the embedding cannot return: rebuild it
    if (flat.length > 256) flat = flat.split('\u001f').join('\u001f');
    flat = flat || fame_json(e);
    dirty = {};
    order = [];
    out = [];
    return flat;
  }
  function fame_json(e) {
    var w = {}, d = [], o = [], k, t;
    for (k in dirty) {
      if (store[k] === undefined) { d.push(k); continue; }
      w[k] = store[k];
      t = typeof store[k];
      if (t === 'function' || t === 'symbol') o.push(k);  // JSON leaves it out
    }
    return JSON.stringify({w: w, d: d, o: o, e: e});  // made in one piece: never a rope
  }
  function fame_next(run) {
    var settled = false;
    return function next(err, value) {
      if (settled) return;
      settled = true;
      if (run === current && err == null && out.length === 0) {
        settledNow = true;
        valueNow = value;
        return;
      }
      fame_settle();
      out.push(['next', run, err == null ? null : String(err && err.message || err),
                value === undefined ? null : value]);
    };
  }
  function fame_settle() {  // the run's next() as an effect, in its place among the others
    if (settledNow) out.push(['next', current, null, valueNow === undefined ? null : valueNow]);
    settledNow = false;
  }
  function fame_fail(run, e) {
    fame_settle();
    var text = e instanceof Error ? e.name + ': ' + e.message : String(e);
    out.push(['throw', run, text, e instanceof Error ? String(e.stack) : '']);
  }
  function fame_run(fn, run, push) {
    if (push) fame_absorb(push);
    current = run;
    try { fn.call(context, fame_next(run)); } catch (e) { fame_fail(run, e); }
    var drained = fame_drain();
    current = 0;
    return drained;
  }
  // A quick script (see quick_source in Python) names every variable it touches and runs
  // on an object of just those, handed over as arguments, whose setters note what it
  // writes: no Proxy trap, no JSON, no store. It can call next only while it runs, so one
  // next serves every quick call.
  var quickSettled = false;
  function fame_quick_call(ctx, run) {  // the head of the outbox, null: effects
    current = run;
    quickSettled = settledNow = false;  // what a call stopped by its time limit left
    try { ctx.fame_body(fame_quick_next); } catch (e) { fame_fail(run, e); }
    return out.length === 0 ? (settledNow ? fame_flat(valueNow) : '') : null;
  }
  function fame_quick_next(err, value) {
    if (quickSettled) return;
    quickSettled = true;
    if (err == null && out.length === 0) { settledNow = true; valueNow = value; return; }
    fame_settle();
    out.push(['next', current, err == null ? null : String(err && err.message || err),
              value === undefined ? null : value]);
  }
  // A quick call's outbox is made by its own generated code (quick_source in Python):
  // 'Q<value passed to next, empty: not called>' then a field per variable it touches:
  // empty when not written, '-' when gone, else the flat value; or, the most usual outcome
  // of all, next() and its one variable set to a finite number or a boolean: that value.
  function fame_quick_flat(v) { return v === undefined ? '-' : fame_flat(v); }
  function fame_quick_finish(result) {
    settledNow = false;
    current = 0;
    // a long string built by += may be a rope, which the embedding cannot return
    if (typeof result === 'string' && result.length > 256) {
      result = result.split('\u001f').join('\u001f');
    }
    return result;
  }
  // What cannot go so (an effect, an object): the written variables (bits of mask) go
  // through the Proxy into the store, and the outbox is fame_drain's.
  function fame_quick_merge(v, written, mask) {
    var i, k, text;
    for (i = 0; i < written.length; i++) {
      if (!(mask & (1 << i))) continue;
      k = written[i];
      if (v[k] === undefined) delete variables[k]; else variables[k] = v[k];
    }
    text = fame_drain();
    current = 0;
    return text;
  }
  function fame_deliver(table, id, msg, push, once) {
    fame_absorb(push);
    var callback = table[id];
    if (once) delete table[id];
    if (callback) {
      try { callback(JSON.parse(msg)); } catch (e) { fame_fail(0, e); }
    }
    return fame_drain();
  }
  return {
    context: context, console: console, environment: environment, node: fame_node,
    hide: fame_hide, run: fame_run, drain: fame_drain,
    quick_call: fame_quick_call, quick_flat: fame_quick_flat, quick_finish: fame_quick_finish,
    quick_merge: fame_quick_merge,
    message: function fame_message(id, msg, push) {
      return fame_deliver(subs, id, msg, push, false);
    },
    response: function fame_response(id, msg, push) {
      return fame_deliver(calls, id, msg, push, true);
    }
  };
})();
var console = __fame.console, environment = __fame.environment;
