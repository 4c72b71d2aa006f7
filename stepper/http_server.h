// `step --serve`: the web page and its JSON API over the recorded frame, on
// 127.0.0.1 only. Every request goes through the session (one at a time);
// bad requests get a 4xx status with {"error": "..."} and never stop the
// server. The connections, limits and deadlines: http_connections.h.
//
//   GET /                      the page (stepper/web/, built in)
//   GET /api/frame             sizes, counts and the `frame` text
//   GET /api/stages            [{name, title, about}]
//   GET /api/stage?name=NAME   a stage image (PNG)
//   GET /api/upto?n=N          the frame after the first N triangles (PNG)
//   GET /api/pixel?x=X&y=Y[&upto=N]  a pixel's history and breakdown (and the `pixel X Y` text),
//                              at the frame's end or after the first N triangles
//   GET /api/tri?n=N           a triangle's setup (and the `tri N` text)
//   GET /api/tile?x=TX&y=TY    a tile's bins (and the `tile TX TY` text)
//   GET /api/texel?id=ID&level=L&x=X&y=Y  one texel's stored and linear values (`texel ID L X Y`)
//   GET /favicon.ico           the tab's icon (drawn in code)
#pragma once

#include "stepper/session.h"

namespace prast::stepper {

// Serves until the process is stopped. Prints the URL on stdout; port 0
// takes any free port. Returns 1 (with a line on stderr naming the port)
// when it cannot listen, e.g. when another server has the port.
int serve(Session& session, int port);

} // namespace prast::stepper
