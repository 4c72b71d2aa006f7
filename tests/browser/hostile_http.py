"""`step --serve` under hostile input, over raw sockets on loopback.

run(port) asserts, against a running server:
- every bad request (malformed or oversized request lines and headers,
  out-of-range, negative, NaN, overflowing or repeated numbers, unknown
  endpoints, bodies on GET, other methods, a foreign or missing Host header,
  another site's Origin or Sec-Fetch-Site)
  gets a 4xx JSON {"error": ...} with a fixed message that never echoes the
  request, and the server keeps answering;
- page files: only the built-in ones, every traversal spelling (plain,
  percent-encoded, backslashes, NUL, absolute-form) is a 404;
- headers: the right Content-Type, nosniff, a Content-Security-Policy, no
  CORS header;
- limits: idle and stalled connections are closed by the server, a
  connection serves at most 20 requests, slow clients trickling bytes do not
  stop others from being served, many connections at once are all answered;
- floods (docs/security.md): a Range header (2,700 ranges, or one) is
  refused with 416, never a partial or multiplied body; a head of 100,000
  header lines is refused with 431 after 16 KiB and the server's memory
  (VmRSS) stays within a few MB; a page load is answered while 64 slow-loris
  connections and 1,000 idle ones are open, and the slow-loris ones are cut
  at the deadline; a burst of 200 connections is answered; clients that
  pipeline requests and read no answer hold no worker; running out of
  descriptors (the server's limit lowered with prlimit) neither stops nor
  spins it; a second `step --serve` on the same port fails naming the port;
- a seeded fuzz loop of a few thousand random and mutated requests;
- the listening socket is 127.0.0.1's only (/proc/net/tcp, and connecting
  through this machine's other addresses is refused).
The server's process is found from its listening socket (/proc/net/tcp
inode -> /proc/PID/fd). Standard library only.
"""
import json
import os
import random
import resource
import select
import socket
import subprocess
import threading
import time

KEEP_ALIVE_REQUESTS = 20  # stepper/http_connections.h kKeepAliveRequests
REQUEST_DEADLINE = 5.0    # kRequestDeadline: a whole request head, from its first byte
MAX_HEADER_LINES = 100    # stepper/http_wire.h kMaxHeaderLines
MAX_HEAD_BYTES = 16384    # kMaxHeadBytes
BUILT_IN = {"/": "text/html; charset=utf-8", "/index.html": "text/html; charset=utf-8",
            "/step.js": "text/javascript; charset=utf-8", "/step.css": "text/css; charset=utf-8"}


# ---- a minimal HTTP/1.1 client over raw sockets

def split_answers(reply):
    """([(status, headers {lower name: value}, body)], the bytes of an answer
    not complete yet)."""
    answers = []
    while reply.startswith(b"HTTP/1."):
        head, sep, rest = reply.partition(b"\r\n\r\n")
        if not sep:
            break
        headers = {}
        for line in head.split(b"\r\n")[1:]:
            name, _, value = line.partition(b":")
            headers[name.strip().lower().decode("latin-1")] = value.strip().decode("latin-1")
        length = int(headers.get("content-length", "0"))
        if len(rest) < length:
            break
        answers.append((int(head.split(b" ")[1]), headers, rest[:length]))
        reply = rest[length:]
    return answers, reply


def parse_answers(reply):
    answers, rest = split_answers(reply)
    assert not rest, ("bytes after the answers", rest[:200])
    return answers


def exchange(port, data, timeout=60, head=False, quiet=0.05):
    """Sends raw bytes and reads the answers until the server closes, or
    until it has been quiet for `quiet` seconds after a complete answer (a
    connection the server keeps alive); none when it closed without one,
    several when the bytes held several requests. (Our side stays open: a
    half-closed client may get no answer.)"""
    reply, reset = b"", False
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as c:
        try:
            c.sendall(data)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the server answered and closed before reading it all
        while True:
            if head:
                complete = reply.endswith(b"\r\n\r\n")
            else:
                answers, rest = split_answers(reply)
                complete = answers and not rest
            c.settimeout(quiet if complete else timeout)
            try:
                b = c.recv(65536)
            except ConnectionResetError:
                # The server closed with bytes of ours unread (a body it
                # refused without reading): the kernel resets the
                # connection and may drop the answer.
                reset = True
                break
            except socket.timeout:
                assert complete, ("no answer within %d s" % timeout, data[:100])
                break
            if not b:
                break
            reply += b
    if head:  # answers without bodies
        return [(int(a.split(b" ")[1]), {}, b"") for a in reply.split(b"\r\n\r\n") if a.startswith(b"HTTP/1.")]
    answers, rest = split_answers(reply)
    assert not rest or reset, ("bytes after the answers", rest[:200])
    return answers


def request_bytes(port, path, method="GET", headers=None):
    """A request's line and headers (Host 127.0.0.1:port and Connection:
    close unless `headers` say otherwise; None removes one)."""
    hdrs = {"Host": "127.0.0.1:%d" % port, "Connection": "close"}
    hdrs.update(headers or {})
    return ("%s %s HTTP/1.1\r\n" % (method, path) + "".join(
        "%s: %s\r\n" % (k, v) for k, v in hdrs.items() if v is not None) + "\r\n").encode("latin-1")


def request(port, path, method="GET", headers=None):
    """One request -> (status, headers, body) of its answer."""
    answers = exchange(port, request_bytes(port, path, method, headers), head=method == "HEAD")
    assert len(answers) >= 1, ("no answer", method, path[:100])
    return answers[0]


def check_error(what, answer, statuses):
    """A 4xx answer in `statuses`, JSON {"error": fixed text}, no echo of the request."""
    status, headers, body = answer
    assert status in statuses, (what, status, body[:200])
    assert headers.get("content-type") == "application/json", (what, headers)
    assert headers.get("x-content-type-options") == "nosniff", (what, headers)
    assert "access-control-allow-origin" not in headers, (what, headers)
    message = json.loads(body.decode())["error"]
    assert 0 < len(message) < 120 and "<" not in message and "\n" not in message, (what, message)
    return message


def check_good(port):
    status, headers, body = request(port, "/api/frame")
    assert status == 200 and headers["content-type"] == "application/json", (status, headers)
    assert json.loads(body.decode())["width"] > 0


# ---- the cases

def host_checks(port):
    good = ["127.0.0.1:%d" % port, "127.0.0.1", "localhost:%d" % port, "localhost", "LocalHost:%d" % port]
    for host in good:
        assert request(port, "/api/frame", headers={"Host": host})[0] == 200, host
    bad = [None, "", "evil.example", "evil.example:%d" % port, "127.0.0.1.evil.example", "localhost.evil.example",
           "localhost.", "127.0.0.1:%d" % (port + 1), "127.0.0.1:", "127.0.0.1:%d0" % port, "[::1]:%d" % port,
           "0.0.0.0:%d" % port, "127.0.0.2:%d" % port, "2130706433:%d" % port, "127.0.0.1:%d evil" % port,
           "evil.example%%00127.0.0.1:%d" % port, "localhost\tx"]
    for host in bad:
        for path in ("/", "/api/frame", "/api/pixel?x=1&y=1", "/step.js"):
            check_error("Host %r" % host, request(port, path, headers={"Host": host}), (403,))
    # Pages of other origins (another site, another server on this
    # machine) as browsers name them: refused; our own page and typed URLs pass.
    ours = ["http://127.0.0.1:%d" % port, "http://localhost:%d" % port]
    for origin in ours:
        assert request(port, "/api/frame", headers={"Origin": origin})[0] == 200, origin
    for site in ("same-origin", "none"):
        assert request(port, "/api/frame", headers={"Sec-Fetch-Site": site})[0] == 200, site
    cross = [{"Origin": o} for o in ("http://evil.example", "http://127.0.0.1:%d" % (port + 1), "null",
                                     "https://127.0.0.1:%d" % port, "http://127.0.0.1")] + \
            [{"Sec-Fetch-Site": s} for s in ("cross-site", "same-site")] + \
            [{"Origin": ours[0], "Sec-Fetch-Site": "cross-site"}]
    for hdrs in cross:
        for path in ("/", "/api/frame", "/api/stage?name=final"):
            check_error(hdrs, request(port, path, headers=hdrs), (403,))
    # Two Host headers, one of them ours: refused too.
    text = ("GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nHost: evil.example\r\nConnection: close\r\n\r\n"
            % port).encode()
    check_error("two Hosts", exchange(port, text)[0], (403,))
    return len(good) + 4 * len(bad) + 4 + 3 * len(cross) + 1


def method_checks(port):
    """Other methods get 405, a GET with a body 400, before any body is
    read: the strict checks announce a body and send none (a body the server
    refuses unread makes the kernel reset the connection, which can drop
    the answer); then the bodies are sent too, and whatever arrives is a
    4xx."""
    n = 0
    for path in ("/", "/index.html", "/api/frame", "/api/pixel?x=1&y=1", "/api/stage?name=final", "/nope"):
        for method in ("POST", "PUT", "DELETE", "PATCH", "OPTIONS", "TRACE", "CONNECT"):
            for length in (None, 0, 3, 5000, 10 ** 15):
                hdrs = {} if length is None else {"Content-Length": str(length)}
                answer = request(port, path, method, hdrs)
                check_error((method, path), answer, (405,))
                assert answer[1]["allow"] == "GET, HEAD"
                n += 1
            for body in (b"x=1", b"A" * 5000, b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"):
                check_answers((method, path), exchange(port, request_bytes(
                    port, path, method, {"Content-Length": str(len(body))}) + body), allow_none=True)
                n += 1
        for method in ("BREW", "get", "G\x00T", "GET\x7f"):
            check_error((method, path), request(port, path, method), (400,))
            n += 1
    # HEAD: the headers of a GET, no body.
    assert request(port, "/api/frame", "HEAD")[0] == 200
    # A GET with a body, by length or chunked: refused.
    for hdrs, body in (({"Content-Length": "3"}, b"abc"), ({"Content-Length": "99999999"}, b"abc"),
                       ({"Transfer-Encoding": "chunked"}, b"3\r\nabc\r\n0\r\n\r\n"),
                       ({"Content-Length": "-5"}, b""), ({"Content-Length": "x"}, b""),
                       ({"Content-Length": "2", "Transfer-Encoding": "chunked"}, b"ab")):
        for path in ("/api/frame", "/", "/api/pixel?x=1&y=1"):
            check_error(("GET body", hdrs, path), request(port, path, "GET", hdrs), (400,))
            check_answers(("GET body", hdrs, path), exchange(port, request_bytes(port, path, "GET", hdrs) + body),
                          allow_none=True)
            n += 2
    return n


def traversal_checks(port):
    for path, mime in BUILT_IN.items():
        status, headers, body = request(port, path)
        assert status == 200 and headers["content-type"] == mime and len(body) > 100, (path, status, headers)
        assert headers["x-content-type-options"] == "nosniff"
        # Text from the model (mesh and material names) is shown as text:
        # the page never builds HTML from strings.
        for sink in (b"innerHTML", b"outerHTML", b"insertAdjacentHTML", b"document.write", b"eval(", b"Function("):
            assert sink not in body, (path, sink)
        if mime.startswith("text/html"):
            csp = headers["content-security-policy"]
            assert "default-src 'self'" in csp and "frame-ancestors 'none'" in csp, csp
    paths = ["/../../etc/passwd", "/../../../../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd",
             "/%2E%2E%2F%2E%2E%2Fetc%2Fpasswd", "/..%2f..%2f..%2fetc%2fpasswd", "/%252e%252e/etc/passwd",
             "/..\\..\\etc\\passwd", "/%5c..%5c..%5cetc%5cpasswd", "/step.js/../../../etc/passwd",
             "/index.html/..", "/./index.html", "//etc/passwd", "/%2fetc%2fpasswd", "/etc/passwd",
             "/index.html%00.png", "/index.html\x00", "/step.js?/../../etc/passwd#", "/STEP.JS", "/step.js.",
             "/web/step.js", "/stepper/web/step.js", "/proc/self/environ", "/%c0%ae%c0%ae/etc/passwd",
             "/..%c0%af..%c0%afetc/passwd", "/.%2e/.%2e/etc/passwd", "/api/../etc/passwd", "/api/stage/../../x",
             "http://127.0.0.1/etc/passwd", "file:///etc/passwd", "*", "etc/passwd", "/index.html;/etc/passwd",
             "/CMakeLists.txt", "/.git/config", "/step.js/", "/index.html/"]
    for path in paths:
        status, headers, body = request(port, path)
        assert b"root:" not in body and b"PATH=" not in body and b"[core]" not in body, path
        if path == "/step.js?/../../etc/passwd#":
            assert status == 200 and headers["content-type"] == BUILT_IN["/step.js"]  # the query is ignored
            continue
        check_error(path, (status, headers, body), (400, 404))
    return len(BUILT_IN) + len(paths)


def number_checks(port, frame):
    w, h, tris = frame["width"], frame["height"], frame["triangles"]
    junk = ["-1", "-0x1", "nan", "NaN", "inf", "-inf", "1e3", "1.0", "0x10", "+1", "%201", "1%20", "%091", "1%00",
            "", "9" * 19, "9" * 400, str(2 ** 63), str(2 ** 63 - 1), str(-2 ** 63), str(2 ** 64), str(2 ** 64 + 5),
            "18446744073709551615", "4294967296", "-4294967296", "\u0661".encode().decode("latin-1"), "%ef%bc%91",
            "1,2", "[1]", "1;2", "<script>alert(1)</script>", "%3cscript%3e"]
    cases = []
    for v in junk:
        cases += ["/api/pixel?x=%s&y=1" % v, "/api/pixel?x=1&y=%s" % v, "/api/tri?n=%s" % v, "/api/upto?n=%s" % v,
                  "/api/tile?x=%s&y=0" % v, "/api/tile?x=0&y=%s" % v, "/api/pixel?x=1&y=1&upto=%s" % v,
                  "/api/texel?id=0&level=%s&x=0&y=0" % v, "/api/texel?id=0&level=0&x=%s&y=0" % v,
                  "/api/texel?id=0&level=0&x=0&y=%s" % v]
    cases += ["/api/pixel?x=%d&y=0" % w, "/api/pixel?x=0&y=%d" % h, "/api/pixel?x=%d&y=%d" % (w, h),
              "/api/tri?n=%d" % tris, "/api/upto?n=%d" % (tris + 1), "/api/upto?n=-1",
              "/api/tile?x=%d&y=0" % frame["tiles_x"], "/api/tile?x=0&y=%d" % frame["tiles_y"],
              "/api/pixel?x=1&x=2&y=1", "/api/pixel?x=1&y=1&y=2", "/api/tri?n=1&n=2", "/api/pixel?y=1", "/api/pixel",
              "/api/pixel?", "/api/pixel?&&&", "/api/pixel?x&y", "/api/pixel?x=&y=", "/api/pixel?X=1&Y=1",
              "/api/stage?name=<script>", "/api/stage?name=../../etc/passwd", "/api/stage?name=final&name=depth",
              "/api/stage?name=%00", "/api/stage?name=" + "A" * 5000, "/api/nope", "/api/", "/api", "/api/frame/x",
              "/api/pixel/1/1", "/apiframe", "/api/frame%00", "/%3cscript%3ealert(1)%3c/script%3e",
              "/api/pixel?x=1&y=1&upto=%d" % (tris + 1), "/api/pixel?x=1&y=1&upto=1&upto=2",
              "/api/texel?id=0&level=0&x=100000&y=0", "/api/texel?id=0&level=0&x=0&y=100000",
              "/api/texel?id=0&level=99&x=0&y=0", "/api/texel?id=0&x=0&y=0", "/api/texel?id=0&level=0&x=0",
              "/api/texel?id=0&level=0&x=0&y=0&x=1", "/api/texel?id=<script>&level=0&x=0&y=0",
              "/api/texel?id=0&id=1&level=0&x=0&y=0", "/api/texel"]
    for path in cases:
        status, headers, body = request(port, path)
        if path == "/api/stage?name=final&name=depth":
            assert status == 200 or 400 <= status < 500  # either one stage or an error: never a crash
            continue
        message = check_error(path, (status, headers, body), (400, 404))
        assert "script" not in message and "passwd" not in message, (path, message)
    # The edges of each range are valid.
    edges = ("/api/pixel?x=0&y=0", "/api/pixel?x=%d&y=%d" % (w - 1, h - 1), "/api/tri?n=0",
             "/api/tri?n=%d" % (tris - 1), "/api/upto?n=0", "/api/upto?n=%d" % tris,
             "/api/tile?x=%d&y=%d" % (frame["tiles_x"] - 1, frame["tiles_y"] - 1),
             "/api/pixel?x=0&y=0&upto=0", "/api/pixel?x=0&y=0&upto=%d" % tris, "/api/texel?id=0&level=0&x=0&y=0")
    for path in edges:
        status, headers, _ = request(port, path)
        assert status == 200 and headers["content-type"] in ("application/json", "image/png"), (path, status)
    return len(cases) + len(edges)


def malformed_checks(port):
    big = b"GET /" + b"a" * 9000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
    check_error("long URI", exchange(port, big)[0], (414,))
    cases = [
        b"GARBAGE\r\n\r\n", b"\x00" * 100 + b"\r\n\r\n", b"GET\r\n\r\n", b"GET /\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n",
        b"GET / HTTP/1.1 extra\r\n\r\n", b"GET  / HTTP/1.1\r\n\r\n", b" GET / HTTP/1.1\r\n\r\n",
        b"GET / HTTP/1.1\r\nHost 127.0.0.1\r\n\r\n", b"GET / HTTP/1.1\r\n: x\r\n\r\n",
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: " + b"y" * 9000 + b"\r\n\r\n",  # a header line over 8192
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"Range: bytes=9-1,x\r\n\r\n",
        b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\nExpect: 100-continue\r\nContent-Length: 5\r\n\r\n",
        bytes(range(256)) * 8 + b"\r\n\r\n",
    ]
    for data in cases:
        answers = exchange(port, data)
        assert len(answers) >= 1, data[:60]
        for a in answers:
            if a[0] != 100:
                check_error(data[:60], a, range(400, 500))
    # Cut requests (no blank line): closed without an answer, or a 4xx.
    for data in (b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\n", b"GET /api/fr", b"\r\n", b"G"):
        for a in exchange(port, data):
            check_error(data, a, range(400, 500))
    # Many small headers: refused with 431 (more below, in flood_checks).
    flood = b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"X-A: b\r\n" * 5000 + b"\r\n"
    check_error("5000 header lines", exchange(port, flood)[0], (431,))
    return len(cases) + 6


def keep_alive_checks(port):
    """One connection serves KEEP_ALIVE_REQUESTS requests, then the server closes it."""
    one = ("GET /api/tile?x=0&y=0 HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % port).encode()
    with socket.create_connection(("127.0.0.1", port), timeout=60) as c:
        served = 0
        for i in range(KEEP_ALIVE_REQUESTS + 5):
            try:
                c.sendall(one)
            except (BrokenPipeError, ConnectionResetError):
                break
            data = b""
            while b"\r\n\r\n" not in data:
                b = c.recv(65536)
                if not b:
                    break
                data += b
            if not data:
                break
            head = data.split(b"\r\n\r\n")[0].decode("latin-1").lower()
            length = int(head.split("content-length:")[1].split("\r\n")[0])
            while len(data.split(b"\r\n\r\n", 1)[1]) < length:
                data += c.recv(65536)
            served += 1
            assert ("connection: close" in head) == (served == KEEP_ALIVE_REQUESTS), (served, head)
        assert served == KEEP_ALIVE_REQUESTS, served
    return served


def wait_closed(c, limit):
    """Reads until the server closes `c`; the bytes it sent (fails after `limit` seconds)."""
    c.settimeout(limit)
    data = b""
    while True:
        try:
            b = c.recv(65536)
        except ConnectionResetError:
            return data
        if not b:
            return data
        data += b


def slow_client_checks(port):
    """Idle, stalled and trickling clients lose their connection; meanwhile
    other clients are served."""
    # Idle (nothing sent) and stalled (half a request) connections are closed
    # by the server (keep-alive and read timeouts, 2 s) without an answer.
    conns = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(40)]
    for i, c in enumerate(conns):
        if i % 2:
            c.sendall(b"GET /api/frame HTTP/1.1\r\nHost: 127")
    check_good(port)  # answered although 40 connections hold the 16 workers' queue
    for c in conns:
        data = wait_closed(c, 60)
        assert data == b"" or parse_answers(data)[0][0] == 400, data[:100]
        c.close()
    # Trickling clients (a header byte every 0.3 s, below the read timeout)
    # hold a worker each; with fewer of them than workers, others are served
    # while all of them are still connected and trickling.
    # The whole head has a deadline (5 s from its first byte): a trickling
    # client may be cut then, never before.
    stop = threading.Event()
    lock = threading.Lock()
    trickling, cut_early = [0], []

    def trickle():
        with socket.create_connection(("127.0.0.1", port), timeout=60) as c:
            start = time.monotonic()
            c.sendall(b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
            sent = 0
            while not stop.is_set():
                try:
                    c.sendall(b"z")
                except (BrokenPipeError, ConnectionResetError):
                    if time.monotonic() - start < REQUEST_DEADLINE:
                        cut_early.append(sent)
                    if sent < 3:  # counted as trickling all the same
                        with lock:
                            trickling[0] += 1
                    return
                sent += 1
                if sent == 3:
                    with lock:
                        trickling[0] += 1
                time.sleep(0.3)

    threads = [threading.Thread(target=trickle) for _ in range(8)]
    for t in threads:
        t.start()
    deadline = time.monotonic() + 60  # a bound, not a measurement: connecting under load may take seconds
    while trickling[0] < 8 and time.monotonic() < deadline:
        time.sleep(0.1)
    assert trickling[0] == 8, trickling
    for _ in range(10):
        check_good(port)
    stop.set()
    for t in threads:
        t.join(60)
    assert not cut_early, ("trickling clients were cut off before the deadline", cut_early)
    # A client slower than the read timeout (a byte every 3 s) is cut off.
    with socket.create_connection(("127.0.0.1", port), timeout=60) as c:
        c.sendall(b"GET /api/frame HTTP/1.1\r\n")
        cut = False
        for _ in range(10):
            time.sleep(3)
            try:
                c.sendall(b"X")
            except (BrokenPipeError, ConnectionResetError):
                cut = True
                break
            c.settimeout(0.01)
            try:
                if c.recv(1) == b"":
                    cut = True
                    break
            except socket.timeout:
                pass
            except ConnectionResetError:
                cut = True
                break
        assert cut, "a client sending a byte every 3 s kept its connection for 30 s"
    return 40 + 8 + 1


def concurrency_checks(port):
    """48 clients at once, each sending 6 requests (good and fuzzed) while 24
    idle connections stall: every request is answered."""
    idle = []
    for _ in range(24):
        c = socket.create_connection(("127.0.0.1", port), timeout=60)
        c.sendall(b"GET /api/frame HTTP/1.1\r\nHost: 127")
        idle.append(c)
    results, lock = [], threading.Lock()

    def client(seed):
        r = random.Random(seed)
        for _ in range(6):
            path = r.choice(["/api/frame", "/api/pixel?x=5&y=7", "/api/tile?x=1&y=1"]) if r.random() < 0.5 \
                else junk_path(r)
            answers = exchange(port, ("GET %s HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n"
                                      % path).encode("latin-1"))
            with lock:
                results.append((path, answers))

    threads = [threading.Thread(target=client, args=(1000 + i,)) for i in range(48)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(300)
    for c in idle:
        c.close()
    assert len(results) == 48 * 6, len(results)
    for path, answers in results:
        check_answers(path[:100], answers)
    # 300 connections opened at once, then closed: the server goes on.
    many = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(300)]
    for c in many:
        c.close()
    check_good(port)
    return len(results) + len(idle) + len(many)


# ---- floods, slow-loris, idle and bursts of connections, the port

def server_pid(port):
    """The pid of the process listening on 127.0.0.1:port (its socket's
    inode in /proc/net/tcp, found among /proc/PID/fd)."""
    inode = None
    for line in open("/proc/net/tcp").read().splitlines()[1:]:
        f = line.split()
        if f[3] == "0A" and f[1] == "0100007F:%04X" % port:
            inode = f[9]
    assert inode, "no listening socket on port %d" % port
    target = "socket:[%s]" % inode
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            for fd in os.listdir("/proc/%s/fd" % pid):
                if os.readlink("/proc/%s/fd/%s" % (pid, fd)) == target:
                    return int(pid)
        except OSError:
            continue
    raise AssertionError("no process holds the socket of port %d" % port)


def rss_kib(pid):
    for line in open("/proc/%d/status" % pid):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS for %d" % pid)


def cpu_seconds(pid):
    f = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")


def tcp_state(sock):
    """The state of our end of `sock` in /proc/net/tcp ("01" established,
    "08" close-wait: the server closed it), None when it is gone."""
    local = "0100007F:%04X" % sock.getsockname()[1]
    for line in open("/proc/net/tcp").read().splitlines()[1:]:
        f = line.split()
        if f[1] == local:
            return f[3]
    return None


def readable_now(socks):
    """Those of `socks` with something to read (or closed), without waiting."""
    poller = select.poll()
    for c in socks:
        poller.register(c, select.POLLIN)
    ready = {fd for fd, _ in poller.poll(0)}
    return [c for c in socks if c.fileno() in ready]


def raise_fd_limit(want):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft != resource.RLIM_INFINITY and soft < want:
        resource.setrlimit(resource.RLIMIT_NOFILE, (want if hard == resource.RLIM_INFINITY else min(want, hard), hard))


def page_load(port):
    """What a browser fetches for the page; the seconds it took."""
    start = time.monotonic()
    for path in ("/", "/step.css", "/step.js", "/favicon.ico", "/api/frame", "/api/stages", "/api/stage?name=final"):
        status, headers, body = request(port, path)
        assert status == 200 and len(body) > 0, (path, status)
    return time.monotonic() - start


def range_checks(port):
    """Range is refused (416, a short JSON error) on every endpoint: never a
    partial body, never the answer once per range."""
    n = 0
    flood = "bytes=" + ",".join(["0-"] * 2700)
    for path in ("/api/tile?x=0&y=0", "/", "/step.js", "/api/stage?name=final"):
        data = request_bytes(port, path, headers={"Range": flood})
        assert len(data) > 8000
        with socket.create_connection(("127.0.0.1", port), timeout=60) as c:
            c.sendall(data)
            reply = wait_closed(c, 60)
        assert len(reply) < 4096, (path, len(reply))
        check_error(("Range flood", path), parse_answers(reply)[0], (416,))
        n += 1
    for path in ("/api/frame", "/api/tile?x=0&y=0", "/api/pixel?x=1&y=1", "/", "/step.js", "/api/stage?name=final"):
        for rng in ("bytes=0-10", "bytes=5-", "bytes=-3", "bytes=0-0,2-2", "items=0-1"):
            answer = request(port, path, headers={"Range": rng})
            check_error(("Range", path, rng), answer, (416,))
            assert "content-range" not in answer[1]
            n += 1
    return n


def flood_checks(port):
    """Head limits: 100 header lines and 16 KiB pass, one more is 431; a
    flood of 100,000 header lines (50 MB) is refused with 431 after 16 KiB
    (answered long before it is all sent), 24 times, and the server's
    resident memory grows by less than 8 MB."""
    pid = server_pid(port)

    def head_with(lines):
        return request_bytes(port, "/api/frame", headers=dict(("X-%03d" % i, "v") for i in range(lines)))

    assert exchange(port, head_with(MAX_HEADER_LINES - 2))[0][0] == 200  # with Host and Connection: 100
    check_error("101 header lines", exchange(port, head_with(MAX_HEADER_LINES - 1))[0], (431,))
    base = request_bytes(port, "/api/frame", headers={"X-Pad": "", "X-Pad2": ""})
    pad = MAX_HEAD_BYTES - len(base)
    exact = request_bytes(port, "/api/frame", headers={"X-Pad": "p" * (pad // 2), "X-Pad2": "p" * (pad - pad // 2)})
    assert len(exact) == MAX_HEAD_BYTES
    assert exchange(port, exact)[0][0] == 200
    over = exact.replace(b"X-Pad: ", b"X-Pad: p", 1)
    check_error("a head of 16385 bytes", exchange(port, over)[0], (431,))

    def header_flood():
        line = b"X-Flood: " + b"v" * 489 + b"\r\n"  # 500 bytes: 100,000 lines are 50 MB
        chunk = line * 128
        sent = 0
        with socket.create_connection(("127.0.0.1", port), timeout=60) as c:
            c.sendall(b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\n")
            reply = b""
            while sent < 100000 * len(line):
                c.sendall(chunk)
                sent += len(chunk)
                if readable_now([c]):
                    break
            reply = wait_closed(c, 60)
        assert sent < 4 << 20, ("no answer after %d bytes" % sent)
        check_error("100,000 header lines", parse_answers(reply)[0], (431,))

    header_flood()
    before = rss_kib(pid)
    for _ in range(24):
        header_flood()
    check_good(port)
    after = rss_kib(pid)
    assert after - before < 8 * 1024, ("VmRSS grew by %d KiB" % (after - before))
    print("hostile: 25 floods of 100,000 header lines: 431 each, VmRSS %d -> %d KiB" % (before, after), flush=True)
    return 6 + 25


class SlowLoris:
    """`count` connections, each sending a header byte a second from one
    thread; records when the server closes each."""

    def __init__(self, port, count):
        self.socks = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(count)]
        self.started = time.monotonic()
        self.closed = {}  # index -> seconds after the first byte
        self.stop = threading.Event()
        for c in self.socks:
            c.sendall(b"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        self.thread = threading.Thread(target=self.run)
        self.thread.start()

    def mark(self, i):
        if i not in self.closed:
            self.closed[i] = time.monotonic() - self.started

    def run(self):
        while not self.stop.is_set() and len(self.closed) < len(self.socks):
            for i, c in enumerate(self.socks):
                if i in self.closed:
                    continue
                try:
                    c.sendall(b"z")
                except OSError:
                    self.mark(i)
            poller = select.poll()  # not select(): descriptors may be past 1024
            index = {}
            for i, c in enumerate(self.socks):
                if i not in self.closed:
                    poller.register(c, select.POLLIN)
                    index[c.fileno()] = i
            for fd, _ in poller.poll(1000):
                i = index[fd]
                c = self.socks[i]
                try:
                    if c.recv(4096) == b"":
                        self.mark(i)
                except OSError:
                    self.mark(i)

    def open_count(self):
        return len(self.socks) - len(self.closed)

    def finish(self, limit):
        self.thread.join(limit)
        self.stop.set()
        self.thread.join(10)
        for c in self.socks:
            c.close()


def slow_loris_checks(port):
    """64 connections sending a header byte a second: a page load is
    answered (within 3 s; about 0.1 s unloaded) while all of them are
    open, and the server cuts each at the head's deadline (5 s)."""
    loris = SlowLoris(port, 64)
    took = page_load(port)
    still_open = loris.open_count()
    assert took < 3, "a page load took %.1f s while 64 slow-loris connections were open" % took
    assert still_open == 64, ("slow-loris connections closed before the page was served", loris.closed)
    loris.finish(30)
    assert len(loris.closed) == 64, "slow-loris connections still open 30 s after their first byte"
    latest = max(loris.closed.values())
    assert min(loris.closed.values()) >= REQUEST_DEADLINE - 0.5, loris.closed
    print("hostile: slow-loris: page load %.2f s with 64 open; all cut %.1f-%.1f s after their first byte"
          % (took, min(loris.closed.values()), latest), flush=True)
    return 64


def idle_checks(port):
    """1,000 idle connections (nothing sent) and 64 slow-loris ones: a page
    load is answered (within 3 s) while the slow-loris ones are open and the
    idle ones have all connected; over the connection cap (1,024) the oldest
    idle ones are closed to let new ones in."""
    raise_fd_limit(4096)
    pid = server_pid(port)
    before = rss_kib(pid)
    idle = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(1000)]
    loris = SlowLoris(port, 64)
    took = page_load(port)
    still_open = loris.open_count()
    readable = readable_now(idle)
    during = rss_kib(pid)
    assert during - before < 16 * 1024, ("VmRSS grew by %d KiB with 1,064 connections" % (during - before))
    assert took < 3, "a page load took %.1f s with 1,000 idle and 64 slow-loris connections" % took
    assert still_open == 64, loris.closed
    loris.finish(30)
    for c in idle:
        c.close()
    check_good(port)
    print("hostile: 1,000 idle + 64 slow-loris connections: page load %.2f s (%d idle ones closed by then), "
          "VmRSS %d -> %d KiB" % (took, len(readable), before, during), flush=True)
    return 1064


def burst_checks(port):
    """200 connections opened at once, then a request on each: every one
    answered (the listen backlog holds them: no SYN retries)."""
    start = time.monotonic()
    conns = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(200)]
    connected = time.monotonic() - start
    for c in conns:
        c.sendall(request_bytes(port, "/api/frame"))
    for c in conns:
        answers = parse_answers(wait_closed(c, 60))
        assert answers and answers[0][0] == 200, answers[:1]
        c.close()
    took = time.monotonic() - start
    assert connected < 1.0, "200 connects took %.1f s (SYN retries: the listen backlog is short)" % connected
    print("hostile: burst: 200 connections in %.2f s, all answered in %.2f s" % (connected, took), flush=True)
    return 200


def slow_reader_checks(port):
    """8 clients (twice the workers) that pipeline 19 requests for a 0.7 MB
    answer each and read nothing: once the server has made the first answer
    of each (and gone quiet), the answers wait for their readers in the
    server, never in a worker, so a page load is answered (within 3 s) while
    all 8 are connected; they are closed after 5 s without reading."""
    pid = server_pid(port)
    # What the answers and the page make once and keep is made before the
    # first measure: what follows measures the waiting answers alone.
    assert request(port, "/api/tile?x=2&y=1")[0] == 200
    page_load(port)
    before = rss_kib(pid)
    one = ("GET /api/tile?x=2&y=1 HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % port).encode()
    conns, connected = [], []
    for _ in range(8):
        c = socket.create_connection(("127.0.0.1", port), timeout=60)
        c.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        connected.append(time.monotonic())
        c.sendall(one * (KEEP_ALIVE_REQUESTS - 1))
        conns.append(c)
    # Quiet: no CPU spent for 0.3 s (a sanitizer build takes longer to get there).
    last, deadline = cpu_seconds(pid), time.monotonic() + 30
    while time.monotonic() < deadline:
        time.sleep(0.3)
        now = cpu_seconds(pid)
        if now - last < 0.02:
            break
        last = now
    took = page_load(port)
    states = [tcp_state(c) for c in conns]
    ages = [time.monotonic() - t for t in connected]
    during = rss_kib(pid)
    assert took < 3, "a page load took %.1f s while 8 clients did not read their answers" % took
    # The server may close a client once it has made no progress for 5 s;
    # its last progress is no earlier than its connect, so one connected
    # less than 5 s ago must still be open (on a slow build making the
    # answers takes longer, and the oldest may rightly be gone).
    early = [(i, st, round(a, 1)) for i, (st, a) in enumerate(zip(states, ages)) if st != "01" and a < 4.9]
    assert not early, ("clients that did not read were closed within 5 s of connecting", early)
    still_open = states.count("01")
    # Bounded while they wait (16 MiB of waiting answers, and what the
    # workers used to make them), and given back once they are gone.
    assert during - before < 256 * 1024, ("VmRSS grew by %d KiB" % (during - before))
    # Closed by the server: our end leaves ESTABLISHED (01) without our
    # reading a byte (reading would count as progress).
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and any(tcp_state(c) == "01" for c in conns):
        time.sleep(0.5)
    states = [tcp_state(c) for c in conns]
    for c in conns:
        c.close()
    assert "01" not in states, ("clients that read nothing were still connected after 60 s", states)
    check_good(port)
    # The server gives memory back when idle (a check every 0.1 s): on a
    # loaded machine that may take more than one look. AddressSanitizer's
    # allocator keeps freed memory in its quarantine instead, so there the
    # bound while they wait is the check.
    sanitized = "libasan" in open("/proc/%d/maps" % pid).read()
    deadline = time.monotonic() + 10
    while True:
        time.sleep(0.5)
        after = rss_kib(pid)
        if sanitized or after - before < 8 * 1024 or time.monotonic() > deadline:
            break
    assert sanitized or after - before < 8 * 1024, ("VmRSS %d KiB before, %d after" % (before, after))
    print("hostile: 8 clients not reading 19 answers each: page load %.2f s with %d of them open, "
          "VmRSS %d -> %d -> %d KiB" % (took, still_open, before, during, after), flush=True)
    return 8 * 19


def fd_shortage_checks(port):
    """The server's descriptor limit lowered below its connection cap
    (prlimit): 300 connections at once make accept() fail with EMFILE; the
    server closes its oldest idle connections to go on, answers a request,
    and does not spin (CPU time over 2 s with the connections open)."""
    pid = server_pid(port)
    old = resource.prlimit(pid, resource.RLIMIT_NOFILE)
    in_use = len(os.listdir("/proc/%d/fd" % pid))
    resource.prlimit(pid, resource.RLIMIT_NOFILE, (in_use + 20, old[1]))
    try:
        conns = [socket.create_connection(("127.0.0.1", port), timeout=60) for _ in range(300)]
        check_good(port)
        cpu = cpu_seconds(pid)
        time.sleep(2)
        spent = cpu_seconds(pid) - cpu
        check_good(port)
        for c in conns:
            c.close()
    finally:
        resource.prlimit(pid, resource.RLIMIT_NOFILE, old)
    assert spent < 0.5, "the server used %.2f s of CPU in 2 s while out of descriptors" % spent
    check_good(port)
    print("hostile: out of descriptors (limit %d): answered, %.2f s of CPU in 2 s" % (in_use + 20, spent), flush=True)
    return 300


def port_clash_checks(port):
    """A second `step --serve` on the same port fails with one line naming
    the port (exit 1); the first goes on answering every request."""
    pid = server_pid(port)
    exe = os.readlink("/proc/%d/exe" % pid)
    args = open("/proc/%d/cmdline" % pid, "rb").read().split(b"\0")[:-1]
    args = [a.decode() for a in args]
    i = args.index("--port")
    args[i + 1] = str(port)
    r = subprocess.run([exe] + args[1:], capture_output=True, text=True, timeout=300)
    assert r.returncode == 1 and "serving" not in r.stdout, (r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "127.0.0.1:%d" % port in lines[0], r.stderr
    for _ in range(20):
        check_good(port)
    print("hostile: a second server on port %d: %s" % (port, lines[0]), flush=True)
    return 21


# ---- the fuzz loop

def check_answers(what, answers, allow_none=False, head=False):
    """A hostile request gets 4xx JSON errors (or, if it is valid after all, 200)."""
    assert answers or allow_none, what
    for status, headers, body in answers:
        assert status == 200 or 400 <= status < 500, (what, status, body[:200])
        if status != 200 and not head:
            check_error(what, (status, headers, body), range(400, 500))


def junk_value(rng):
    kinds = [
        lambda: "9" * rng.randint(10, 400),                    # huge
        lambda: "-" + str(rng.randint(1, 10 ** 6)),             # negative
        lambda: rng.choice(["nan", "NaN", "inf", "-inf", "1e308", "-0.0", "0x1f", "1.5", "+1", " 1", "1 "]),
        lambda: "".join(rng.choice("%0123456789abcdefzg") for _ in range(rng.randint(1, 12))),  # percent junk
        lambda: rng.choice(["%00", "%ff%fe", "%c3%28", "%", "%%", "%2", "%0d%0a", "%e2%80%ae", "%7f"]),
        lambda: "A" * rng.randint(1000, 7000),                 # overlong
        lambda: "",
        lambda: str(rng.randint(0, 400)),                      # sometimes valid
        lambda: str(2 ** 63) + rng.choice(["", "0", "1"]),
    ]
    return rng.choice(kinds)()


def junk_path(rng):
    segments = ["api", "pixel", "tri", "tile", "upto", "stage", "frame", "stages", "..", ".", "", "%2e%2e",
                "index.html", "step.js", "%00", "%5c", "\\", "\u00e9".encode().decode("latin-1"),
                "a" * rng.randint(1, 300)]
    path = "/" + "/".join(rng.choice(segments) for _ in range(rng.randint(0, 4)))
    if rng.random() < 0.8:
        keys = ["x", "y", "n", "name", "", "x[]", "%78"]
        path += "?" + "&".join("%s=%s" % (rng.choice(keys), junk_value(rng)) for _ in range(rng.randint(0, 4)))
    return path


def mutate(rng, data):
    """A valid request with a few bytes flipped, inserted, deleted or repeated."""
    data = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        i = rng.randrange(len(data))
        op = rng.randrange(5)
        if op == 0:
            data[i] = rng.randrange(256)
        elif op == 1:
            data[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
        elif op == 2:
            del data[i:i + rng.randint(1, 8)]
        elif op == 3:
            data[i:i] = data[i:i + rng.randint(1, 40)] * rng.randint(2, 50)
        else:
            data[i:i] = rng.choice([b"\r\n", b"\n", b"\r", b"\x00", b":", b" ", b"%", b"?", b"&", b"="])
        if not data:
            data = bytearray(b"\r\n")
    return bytes(data)


def fuzz_checks(port, count=2400, clients=8):
    """`clients` threads, each sending count/clients requests from its own
    seeded generator (the requests are the same on every run; a request
    the server waits on, cut by a mutation, costs its read timeout, so they
    overlap)."""
    failures = []

    def client(seed):
        try:
            fuzz_client(port, random.Random(seed), count // clients)
        except BaseException as e:  # reported by the main thread
            failures.append(e)

    threads = [threading.Thread(target=client, args=(12 + k,)) for k in range(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(600)
    if failures:
        raise failures[0]
    assert not any(t.is_alive() for t in threads), "fuzz clients still running after 600 s"
    return count // clients * clients


def fuzz_client(port, rng, count):
    valid = [("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n\r\n" % (p, port)).encode()
             for p in ("/api/frame", "/api/pixel?x=10&y=20", "/api/tri?n=7", "/api/tile?x=1&y=0",
                       "/api/upto?n=100", "/api/stage?name=depth", "/step.js", "/")]
    for i in range(count):
        if i % 2:
            data = mutate(rng, rng.choice(valid))
            check_answers(data[:100], exchange(port, data), allow_none=True)
            continue
        method = rng.choice(["GET"] * 6 + ["POST", "PUT", "DELETE", "OPTIONS", "PATCH", "HEAD", "BREW"])
        path = junk_path(rng)
        headers = rng.choice(["Host: 127.0.0.1\r\n", "Host: localhost:%d\r\n" % port, "Host: evil.example\r\n", ""])
        headers += "Connection: close\r\n"
        body = b""
        if rng.random() < 0.2:
            body = bytes(rng.randrange(256) for _ in range(rng.choice([0, 10, 5000])))
            headers += "Content-Length: %d\r\n" % len(body)
        if rng.random() < 0.1:
            headers += "X-Junk: " + "j" * rng.randint(1, 9000) + "\r\n"
        data = ("%s %s HTTP/1.1\r\n%s\r\n" % (method, path, headers)).encode("latin-1") + body
        check_answers(path[:100], exchange(port, data, head=method == "HEAD"), allow_none=bool(body),
                      head=method == "HEAD")
    for _ in range(count // 50):
        data = bytes(rng.randrange(256) for _ in range(rng.randint(1, 2000))) + b"\r\n\r\n"
        check_answers(data[:40], exchange(port, data), allow_none=True)


# ---- the listening socket

def local_addresses():
    """This machine's IPv4 addresses other than 127.x (from /proc/net/fib_trie)."""
    found = set()
    try:
        lines = open("/proc/net/fib_trie").read().splitlines()
    except OSError:
        return found
    for prev, line in zip(lines, lines[1:]):
        if line.strip() == "/32 host LOCAL":
            addr = prev.strip().split()[-1]
            if not addr.startswith("127."):
                found.add(addr)
    return found


def check_loopback_only(port):
    """The listening socket is 127.0.0.1's alone: /proc/net/tcp lists it at
    127.0.0.1 (0100007F) and nowhere else, tcp6 not at all; connecting
    through another loopback address or this machine's other addresses is
    refused."""
    listeners = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = open(table).read().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            f = line.split()
            local, state = f[1], f[3]
            if state == "0A" and int(local.rsplit(":", 1)[1], 16) == port:
                listeners.append((table, local.rsplit(":", 1)[0]))
    assert listeners == [("/proc/net/tcp", "0100007F")], listeners
    others = sorted(local_addresses()) + ["127.0.0.2"]
    for addr in others:
        try:
            socket.create_connection((addr, port), timeout=10).close()
            raise AssertionError("the server answers on %s: it is not bound to 127.0.0.1 alone" % addr)
        except OSError:  # refused (or, behind a firewall, timed out)
            pass
    return others


def run(port, frame):
    """All of the above; prints one line per group."""
    groups = [("Host header", host_checks), ("methods and bodies", method_checks),
              ("page files and traversal", traversal_checks), ("numbers", lambda p: number_checks(p, frame)),
              ("malformed requests", malformed_checks), ("keep-alive limit", keep_alive_checks),
              ("slow and idle clients", slow_client_checks), ("concurrent clients", concurrency_checks),
              ("Range", range_checks), ("head floods", flood_checks), ("slow-loris", slow_loris_checks),
              ("idle connections", idle_checks), ("connection burst", burst_checks), ("clients that do not read", slow_reader_checks),
              ("out of descriptors", fd_shortage_checks), ("port clash", port_clash_checks),
              ("fuzz", fuzz_checks)]
    for name, check in groups:
        start = time.monotonic()
        n = check(port)
        check_good(port)
        print("hostile: %s: %d requests or connections, every bad one a 4xx JSON error, server still answering "
              "(%.1f s)" % (name, n, time.monotonic() - start), flush=True)
    others = check_loopback_only(port)
    print("hostile: listening on 127.0.0.1 only (refused on %s)" % ", ".join(others), flush=True)
