"""The shop-floor workflow in real headless Chromium (Debian's `chromium`, driven by Playwright
for Python with `executable_path`; no browser download): a new setup, its tap test fitted, the
lobes with the recommended cut (timed from the click to the drawn diagram), a refused upload's
message, a recording judged, then on the example setup a learning run with progress, a cancel,
and the diagnosis in plain words. Screenshots of every screen go to the given folder.

usage: workflow.py BASE_URL SCREENSHOT_DIR TAP_TEST_FILE RECORDING_FILE BAD_FILE
Prints `lobes_ms <click event to painted frame, ms> <handler to painted frame, ms>` lines and `ok` at the end."""

import json
import sys

from playwright.sync_api import expect, sync_playwright

base, shots, tap, recording, bad = sys.argv[1:6]
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--no-first-run", "--disable-sync"]


def shot(page, name):
    page.screenshot(path=f"{shots}/{name}.png", full_page=True)


def message(page, kind, text, timeout=60_000):
    box = page.locator(f"#message.{kind}")
    expect(box).to_contain_text(text, timeout=timeout)
    return box.inner_text()


with sync_playwright() as p:
    import tempfile
    profile = tempfile.mkdtemp(prefix="chatter-chromium-")
    context = p.chromium.launch_persistent_context(
        profile, executable_path="/usr/bin/chromium", headless=True, args=FLAGS,
        viewport={"width": 1280, "height": 1000})
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    requests = []
    page.on("request", lambda r: requests.append(r.url))
    page.goto(base)

    # 1. machine & tool: a new setup and its tap test
    page.click("#new-setup-box summary")
    page.fill("#new-setup input[name=name]", "Browser test mill")
    page.fill("#new-setup input[name=machine]", "VMC 3")
    page.click("#new-setup button[type=submit]")
    message(page, "ok", "setup created")
    page.set_input_files("#frf-form input[name=file]", tap)
    page.click("#fit-button")
    message(page, "ok", "fitted")
    expect(page.locator("#fit-table")).to_contain_text("720")
    expect(page.locator("#overlay-chart svg")).to_be_visible()
    shot(page, "01-machine-and-tool")

    # a bad upload: the message on the page, nothing stored (the API tests count the rows)
    page.set_input_files("#frf-form input[name=file]", bad)
    page.click("#fit-button")
    text = message(page, "error", "must end in")
    print("bad upload message:", text)
    shot(page, "02-bad-upload")

    # 2. lobes, timed from the click to the drawn diagram, twice (the first computes)
    page.click("#tabs button[data-screen=lobes]")
    for attempt in range(2):
        page.evaluate("document.getElementById('lobes-chart').replaceChildren();"
                      "document.getElementById('show-lobes').addEventListener('mousedown',"
                      " e => { window.lobesClick = e.timeStamp; }, {once: true, capture: true})")
        page.click("#show-lobes")
        page.wait_for_selector("#lobes-chart svg .lobe-line")
        page.wait_for_selector("#recommended-cut")
        # from the click event to the frame after the diagram was drawn
        painted = page.evaluate("new Promise(r => requestAnimationFrame(t => setTimeout(() => r(performance.now()), 0)))")
        click = page.evaluate("window.lobesClick")
        inpage = float(page.get_attribute("#lobes-time", "data-ms"))
        print(f"lobes_ms {painted - click:.1f} {inpage:.1f}")
    expect(page.locator("#recommended-cut")).to_contain_text("Recommended cut")
    box = page.locator("#lobes-chart svg").bounding_box()
    page.mouse.move(box["x"] + 0.45 * box["width"], box["y"] + 0.6 * box["height"])
    expect(page.locator("#tooltip")).to_contain_text("limiting depth")
    shot(page, "03-lobes-hover")
    page.mouse.click(box["x"] + 0.45 * box["width"], box["y"] + 0.75 * box["height"])
    message(page, "ok", "Proposed cut")

    # 3. cut log: the proposed cut's recording judged
    page.click("#tabs button[data-screen=cuts]")
    # the proposal filled speed and depth; the recording at hand was made at 6000 rpm
    page.fill("#recording-form input[name=speed_rpm]", "6000")
    page.set_input_files("#recording-form input[name=file]", recording)
    page.click("#judge-button")
    message(page, "ok", "recording judged")
    expect(page.locator("#verdict")).to_have_text("chatter")
    expect(page.locator("#detection-result h3")).to_contain_text("812")
    expect(page.locator("#cut-table")).to_contain_text("detected")
    shot(page, "04-cut-log")

    # 4. learn on the example setup (its cut log of 32 cuts and 8 poles)
    example = page.locator("#setup-select option", has_text="Example")
    page.select_option("#setup-select", value=example.get_attribute("value"))
    page.click("#tabs button[data-screen=learn]")
    page.fill("#learn-form input[name=update_samples]", sys.argv[6] if len(sys.argv) > 6 else "200")
    page.click("#learn-button")
    expect(page.locator("#job-progress")).to_be_visible()
    page.click("#cancel-job")
    message(page, "ok", "cancelled", timeout=120_000)
    page.click("#learn-button")
    expect(page.locator("#job-stage")).to_contain_text(":", timeout=30_000)
    shot(page, "05-learn-progress")
    message(page, "ok", "finished", timeout=1_500_000)
    expect(page.locator("#diagnosis-summary")).to_be_visible()
    print("diagnosis:", page.locator("#diagnosis-summary").inner_text().replace("\n", " | "))
    shot(page, "06-learn-diagnosis")

    # 5. export
    page.click("#tabs button[data-screen=export]")
    expect(page.locator("#export-links")).to_contain_text("diagnosis.json")
    shot(page, "07-export")

    foreign = [u for u in requests if not u.startswith(base)]
    assert not foreign, f"requests outside the server: {foreign}"
    assert not errors, f"script errors: {errors}"
    context.close()
    print("ok")
