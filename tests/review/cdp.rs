//! Driving headless Chromium over the DevTools protocol, so that a test uses the review page as a
//! reviewer does: real mouse clicks, wheel turns and key presses, which go through the browser's
//! hit testing, focus and default actions, where a `--dump-dom` run only sees the first draw.
//!
//! Chromium runs with `--remote-debugging-pipe`: it reads commands from its file descriptor 3
//! and writes answers and events to its descriptor 4, each a JSON object ended by a NUL byte. A
//! pipe needs no WebSocket client and no port, so no crate beyond serde_json. Every wait has a
//! deadline and names what it awaited when it runs out; the browser is killed when the
//! [`Browser`] is dropped, also when a test panics.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Write};
use std::os::fd::{AsRawFd, OwnedFd, RawFd};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

use crate::chromium;

/// The longest one answer or one awaited state may take: a cold start on a loaded two-core
/// machine is a few seconds; a minute means something hangs.
const TIMEOUT: Duration = Duration::from_secs(60);

/// How many times [`Browser::open`] starts a Chromium that died before its first answer.
const STARTS: u32 = 3;

/// Why a command has no result.
enum NoAnswer {
    /// The protocol's error: the command was refused.
    Refused(String),
    /// Chromium closed its pipe: how it ended and its last words.
    Gone(String),
}

/// A headless Chromium with one tab, attached.
pub struct Browser {
    child: Child,
    commands: File,
    /// Each message Chromium wrote, parsed by a reader thread, so that a wait can time out.
    messages: Receiver<Result<Value, String>>,
    next_id: u64,
    /// The tab's session, once attached: commands to the page carry it.
    session: Option<String>,
    /// The profile (`profile/`) and what Chromium writes on stderr (`stderr.log`).
    dir: tempfile::TempDir,
}

impl Browser {
    /// Starts Chromium in a `width`×`height` window, opens `url` in a new tab and waits until
    /// the document has loaded and the page's own `ready` expression is true.
    pub fn open(url: &str, width: u32, height: u32, ready: &str) -> Browser {
        // Chromium now and then dies of SIGSEGV before it answers anything when several start at
        // once on a busy machine (seen with nine at a time on two cores). Nothing of the page has
        // run by then, so such a start is tried again, a bounded number of times.
        let mut starts = 1;
        let (mut browser, target) = loop {
            let mut browser = Browser::start(width, height);
            match browser.send("Target.createTarget", json!({ "url": "about:blank" })) {
                Ok(target) => break (browser, target),
                Err(NoAnswer::Gone(why)) if starts < STARTS => eprintln!("chromium died at start: {why}"),
                Err(NoAnswer::Gone(why) | NoAnswer::Refused(why)) => {
                    panic!("chromium failed at start ({starts} tries), the last time: {why}")
                }
            }
            starts += 1;
        };
        let attached = browser.call(
            "Target.attachToTarget",
            json!({ "targetId": target["targetId"], "flatten": true }),
        );
        browser.session = Some(attached["sessionId"].as_str().expect("a session id").to_owned());
        browser.call("Page.enable", json!({}));
        browser.navigate(url, ready);
        browser
    }

    /// Chromium started with the pipes on its descriptors 3 and 4, before any command.
    fn start(width: u32, height: u32) -> Browser {
        let dir = tempfile::tempdir().expect("a folder for the profile");
        let stderr = File::create(dir.path().join("stderr.log")).expect("a log file");
        // Close-on-exec in this process, so that no other child started meanwhile (tests run in
        // parallel) holds an end open; only the two ends moved to 3 and 4 reach Chromium.
        let pipe = || rustix::pipe::pipe_with(rustix::pipe::PipeFlags::CLOEXEC).expect("a pipe");
        let (its_commands, commands) = pipe();
        let (messages, its_messages) = pipe();
        let fds = [its_commands.as_raw_fd(), its_messages.as_raw_fd()];
        let mut command = Command::new(chromium::chromium());
        command
            .args(chromium::FLAGS)
            .args(["--remote-debugging-pipe", &format!("--window-size={width},{height}")])
            .arg(format!("--user-data-dir={}", dir.path().join("profile").display()))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(stderr);
        // SAFETY: between fork and exec the closure calls only fcntl and dup2, which are
        // async-signal-safe, and allocates nothing.
        unsafe { command.pre_exec(move || onto_3_and_4(fds)) };
        let child = command.spawn().expect("chromium starts");
        drop((its_commands, its_messages));
        Browser {
            child,
            commands: File::from(commands),
            messages: read_messages(messages),
            next_id: 0,
            session: None,
            dir,
        }
    }

    /// Opens `url` in the tab and waits until the document has loaded and `ready` is true
    /// (which must be false on the page that was open before).
    pub fn navigate(&mut self, url: &str, ready: &str) {
        let navigated = self.call("Page.navigate", json!({ "url": url }));
        assert!(navigated.get("errorText").is_none(), "navigating to {url}: {navigated}");
        self.wait_for(
            &format!("{url} to load"),
            &format!("document.readyState === 'complete' && ({ready})"),
        );
    }

    /// Sends one command (to the tab, once attached) and returns its result.
    fn call(&mut self, method: &str, params: Value) -> Value {
        let sent = params.to_string();
        match self.send(method, params) {
            Ok(result) => result,
            Err(NoAnswer::Refused(error)) => panic!("chromium refused {method} {sent}: {error}"),
            Err(NoAnswer::Gone(why)) => panic!("chromium closed its pipe awaiting {method}: {why}"),
        }
    }

    /// Sends one command and waits for its answer, passing over events (which nothing here
    /// awaits); panics when none comes within [`TIMEOUT`].
    fn send(&mut self, method: &str, params: Value) -> Result<Value, NoAnswer> {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({ "id": id, "method": method, "params": params });
        if let Some(session) = &self.session {
            message["sessionId"] = json!(session);
        }
        let mut bytes = message.to_string().into_bytes();
        bytes.push(0);
        if self.commands.write_all(&bytes).is_err() {
            return Err(NoAnswer::Gone(self.last_words()));
        }
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let reply = match self
                .messages
                .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            {
                Ok(Ok(reply)) => reply,
                Ok(Err(e)) => panic!("awaiting the answer to {method}: {e}"),
                Err(RecvTimeoutError::Timeout) => panic!(
                    "chromium did not answer {method} within {TIMEOUT:?}: {}",
                    self.last_words()
                ),
                Err(RecvTimeoutError::Disconnected) => return Err(NoAnswer::Gone(self.last_words())),
            };
            if reply["id"] == id {
                return match reply.get("error") {
                    Some(error) => Err(NoAnswer::Refused(error.to_string())),
                    None => Ok(reply["result"].clone()),
                };
            }
        }
    }

    /// The value of a JavaScript expression in the page (promises awaited); panics with the
    /// page's message if it throws.
    pub fn eval(&mut self, expression: &str) -> Value {
        self.try_eval(expression)
            .unwrap_or_else(|error| panic!("`{expression}`: {error}"))
    }

    /// [`Browser::eval`], with what it threw (or why the page could not run it: it is being
    /// replaced) as an `Err`.
    fn try_eval(&mut self, expression: &str) -> Result<Value, String> {
        let params = json!({ "expression": expression, "returnByValue": true, "awaitPromise": true });
        let result = match self.send("Runtime.evaluate", params) {
            Ok(result) => result,
            Err(NoAnswer::Refused(error)) => return Err(error),
            Err(NoAnswer::Gone(why)) => panic!("chromium closed its pipe evaluating `{expression}`: {why}"),
        };
        match result.get("exceptionDetails") {
            Some(exception) => Err(format!("threw {}", exception["exception"]["description"])),
            None => Ok(result["result"]["value"].clone()),
        }
    }

    /// Polls `expression` until it is neither null, false nor empty, and returns its value;
    /// panics naming `what` after [`TIMEOUT`].
    pub fn wait_for(&mut self, what: &str, expression: &str) -> Value {
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let value = self.try_eval(expression);
            match &value {
                Ok(Value::Null | Value::Bool(false)) => {}
                Ok(Value::String(text)) if text.is_empty() => {}
                Ok(value) => return value.clone(),
                // Not yet there: the document is being replaced, or the element not yet made.
                Err(_) => {}
            }
            assert!(
                Instant::now() < deadline,
                "waited {TIMEOUT:?} for {what}: `{expression}` is still {value:?}"
            );
            std::thread::sleep(Duration::from_millis(25));
        }
    }

    /// The centre of the element `selector` finds, in the window's CSS pixels.
    pub fn centre(&mut self, selector: &str) -> (f64, f64) {
        let quoted = json!(selector);
        let centre = self.eval(&format!(
            "(() => {{ const e = document.querySelector({quoted}); if (!e) return null; \
             const r = e.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; }})()"
        ));
        match centre.as_array().map(|xy| (xy[0].as_f64(), xy[1].as_f64())) {
            Some((Some(x), Some(y))) => (x, y),
            _ => panic!("the page has no `{selector}`"),
        }
    }

    /// Moves the mouse to the centre of `selector` and clicks its left button there.
    pub fn click(&mut self, selector: &str) {
        let (x, y) = self.centre(selector);
        self.click_at(x, y);
    }

    /// A left click at `(x, y)`: the mouse moves there, is pressed and released.
    pub fn click_at(&mut self, x: f64, y: f64) {
        self.move_to(x, y);
        for kind in ["mousePressed", "mouseReleased"] {
            self.call(
                "Input.dispatchMouseEvent",
                json!({ "type": kind, "x": x, "y": y, "button": "left", "clickCount": 1 }),
            );
        }
    }

    /// Moves the mouse to `(x, y)`, in the window's CSS pixels.
    pub fn move_to(&mut self, x: f64, y: f64) {
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": "mouseMoved", "x": x, "y": y }),
        );
    }

    /// One notch of the mouse wheel at `(x, y)`, turned away from the user (up).
    pub fn wheel_up(&mut self, x: f64, y: f64) {
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": "mouseWheel", "x": x, "y": y, "deltaX": 0, "deltaY": -120 }),
        );
    }

    /// Presses and releases a key: `Home`, `End`, `ArrowLeft`, `ArrowDown` or a letter (the
    /// virtual key code is what moves a focused slider or menu).
    pub fn press(&mut self, key: &str) {
        let (code, virtual_key) = match key {
            "End" => (key.to_owned(), 35),
            "Home" => (key.to_owned(), 36),
            "ArrowLeft" => (key.to_owned(), 37),
            "ArrowDown" => (key.to_owned(), 40),
            letter if letter.len() == 1 && letter.as_bytes()[0].is_ascii_alphabetic() => {
                let upper = letter.to_ascii_uppercase();
                (format!("Key{upper}"), u32::from(upper.as_bytes()[0]))
            }
            other => panic!("no key code for `{other}`"),
        };
        let mut down = json!({ "type": "keyDown", "key": key, "code": code, "windowsVirtualKeyCode": virtual_key });
        if key.len() == 1 {
            down["text"] = json!(key);
        }
        self.call("Input.dispatchKeyEvent", down);
        self.call(
            "Input.dispatchKeyEvent",
            json!({ "type": "keyUp", "key": key, "code": code, "windowsVirtualKeyCode": virtual_key }),
        );
    }

    /// What the window shows now, also written to `file` as a PNG for a person to look at.
    pub fn screenshot(&mut self, file: &Path) -> goldray::rgb_image::RgbImage {
        let shot = self.call("Page.captureScreenshot", json!({ "format": "png" }));
        let png = base64_decode(shot["data"].as_str().expect("the screenshot's data"));
        std::fs::write(file, &png).unwrap_or_else(|e| panic!("writing {}: {e}", file.display()));
        // Decoded from memory: another run of the same test may be writing the same file.
        match goldray::rgb_image::decode_png(&png, u64::MAX) {
            Ok(decoded) => decoded.image,
            Err(e) => panic!("the screenshot: {e}"),
        }
    }

    /// Whether Chromium still runs, and the end of what it wrote on stderr: why it went quiet.
    fn last_words(&mut self) -> String {
        let status = match self.child.try_wait() {
            Ok(Some(status)) => format!("it exited ({status})"),
            _ => "it still runs".to_owned(),
        };
        let log = std::fs::read_to_string(self.dir.path().join("stderr.log")).unwrap_or_default();
        let lines: Vec<&str> = log.lines().collect();
        let tail = lines[lines.len().saturating_sub(20)..].join("\n");
        format!("{status}; the end of its stderr:\n{tail}")
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// In the child, between fork and exec: the command pipe's read end becomes descriptor 3 and
/// the message pipe's write end descriptor 4, both left open across exec.
fn onto_3_and_4(fds: [RawFd; 2]) -> io::Result<()> {
    let check = |result: i32| {
        if result < 0 {
            Err(io::Error::last_os_error())
        } else {
            Ok(result)
        }
    };
    // Each first moves above 4, so that placing one on 3 cannot close the other if it was 3.
    let mut high = [0; 2];
    for (moved, fd) in high.iter_mut().zip(fds) {
        // SAFETY: fcntl on a descriptor this process owns; no memory is passed.
        *moved = check(unsafe { libc::fcntl(fd, libc::F_DUPFD_CLOEXEC, 5) })?;
    }
    for (fd, target) in high.into_iter().zip([3, 4]) {
        // SAFETY: as above; dup2 replaces whatever the child had at 3 and 4.
        check(unsafe { libc::dup2(fd, target) })?;
        check(unsafe { libc::fcntl(target, libc::F_SETFD, 0) })?;
    }
    Ok(())
}

/// A thread that parses each NUL-ended message until Chromium closes its end.
fn read_messages(pipe: OwnedFd) -> Receiver<Result<Value, String>> {
    let (sender, receiver) = channel();
    std::thread::spawn(move || {
        for message in BufReader::new(File::from(pipe)).split(0) {
            let parsed = message
                .map_err(|e| format!("reading chromium's pipe: {e}"))
                .and_then(|bytes| {
                    serde_json::from_slice(&bytes)
                        .map_err(|e| format!("chromium wrote {}: {e}", String::from_utf8_lossy(&bytes)))
                });
            let failed = parsed.is_err();
            if sender.send(parsed).is_err() || failed {
                break;
            }
        }
    });
    receiver
}

/// Standard base64 with padding, which is how the protocol carries a screenshot's bytes.
fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("`{}` in base64", char::from(c)),
    };
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    for chunk in text.trim_end_matches('=').as_bytes().chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &c)| n | u32::from(value(c)) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}
