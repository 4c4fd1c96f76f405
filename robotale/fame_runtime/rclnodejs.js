// rclnodejs' node API for FAME's scripts (`environment.variables.node`), on robotale's bus.
// What a script does with it is an effect in the runtime's outbox, which
// robotale/fame_runtime/rclnodejs.py applies; javascript.js, evaluated after this file, hands
// it the outbox and the tables of the subscriptions' and service calls' callbacks. Every
// function is named fame_* so that an error's stack can be cut down to the script's own lines.
function fame_rclnodejs(effect, subs, calls, console) {
  var ids = 0;
  return function fame_node(name) {
    return {
      name: function fame_name() { return name; },
      namespace: function fame_namespace() { return '/' + name; },
      getLogger: function fame_logger() { return console; },
      createPublisher: function fame_publisher(type, topic) {
        return {topic: topic, publish: function fame_publish(msg) {
          effect(['pub', topic, type, msg]); }};
      },
      createSubscription: function fame_subscription(type, topic, options, callback) {
        var id = ++ids;
        subs[id] = typeof options === 'function' ? options : callback;
        effect(['sub', id, topic, type]);
        return {id: id, topic: topic};
      },
      destroySubscription: function fame_destroy(s) {
        if (s && subs[s.id]) { delete subs[s.id]; effect(['unsub', s.id]); }
      },
      createClient: function fame_client(type, service) {
        return {
          waitForService: function fame_wait() { return Promise.resolve(true); },
          isServiceServerAvailable: function fame_available() { return true; },
          sendRequest: function fame_request(request, callback) {
            var id = ++ids;
            calls[id] = callback;
            effect(['req', id, service, type, request]);
          }
        };
      }
    };
  };
}
