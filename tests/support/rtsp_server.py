#!/usr/bin/python3
"""A real RTSP server for tests: serves a video file as live H.264 (or Motion JPEG) streams.

Run with Debian's /usr/bin/python3 (python3-gi); it needs gir1.2-gst-rtsp-server-1.0 and the
GStreamer plugins base, good, ugly (x264enc) and libav (decoders), see tools/setup.sh.

    rtsp_server.py --video FILE [--mount NAME]... [--port 0] [--width W --height H]
                   [--frames N] [--fps F] [--loop] [--codec h264|jpeg]

The video is decoded once (scaled, at most --frames frames) and kept in memory. Each client of a
mount gets its own session from the first frame, pushed at the video's rate with timestamps on
the pipeline clock, as a camera delivers them (live: nothing is sent faster than real time);
with --loop it starts again at the end, without it the stream ends (RTCP BYE) after the last
frame. Once listening it prints `ready rtsp://127.0.0.1:PORT` and one `mount rtsp://...` line
per mount on stdout; on a failure it prints `error: WHAT` and exits 1. SIGTERM and SIGINT stop
it (SIGKILL too, as a server that goes away). Exit codes: 0 stopped, 1 failed, 2 bad arguments.
"""

import argparse
import signal
import sys


def fail(what):
    print("error: " + what, flush=True)
    sys.exit(1)


try:
    import gi

    gi.require_version("Gst", "1.0")
    gi.require_version("GstRtspServer", "1.0")
    from gi.repository import GLib, Gst, GstRtspServer
except (ImportError, ValueError) as e:
    fail("GStreamer's RTSP server is not installed (gir1.2-gst-rtsp-server-1.0): %s" % e)


def decode_video(path, width, height, max_frames):
    """The video's frames as I420 buffers, its caps and its frame rate (num, den)."""
    scale = "videoscale ! " if width and height else ""
    size = ",width=%d,height=%d,pixel-aspect-ratio=1/1" % (width, height) if width else ""
    pipeline = Gst.parse_launch(
        "filesrc name=file ! decodebin ! videoconvert ! %s"
        "video/x-raw,format=I420%s ! appsink name=sink sync=false" % (scale, size)
    )
    pipeline.get_by_name("file").set_property("location", path)
    sink = pipeline.get_by_name("sink")
    pipeline.set_state(Gst.State.PLAYING)
    frames, caps = [], None
    while max_frames <= 0 or len(frames) < max_frames:
        sample = sink.emit("try-pull-sample", 10 * Gst.SECOND)
        if sample is None:
            break
        caps = sample.get_caps()
        frames.append(sample.get_buffer().copy_deep())
    bus = pipeline.get_bus()
    message = bus.pop_filtered(Gst.MessageType.ERROR)
    pipeline.set_state(Gst.State.NULL)
    if not frames:
        detail = message.parse_error()[0].message if message else "no frame decoded"
        fail("cannot decode %s: %s" % (path, detail))
    structure = caps.get_structure(0)
    ok, num, den = structure.get_fraction("framerate")
    if not ok or num <= 0:
        num, den = 30, 1
    return frames, caps, (num, den)


class VideoFactory(GstRtspServer.RTSPMediaFactory):
    """One live session per client: the frames from the first, at the video's rate."""

    def __init__(self, frames, caps, rate, loop, codec):
        super().__init__()
        self.frames, self.loop, self.rate = frames, loop, rate
        size = caps.get_structure(0)
        self.caps = "video/x-raw,format=I420,width=%d,height=%d,framerate=%d/%d" % (
            size.get_int("width")[1],
            size.get_int("height")[1],
            rate[0],
            rate[1],
        )
        key_interval = max(1, rate[0] // max(1, rate[1]))  # a keyframe every second
        if codec == "h264":
            # One slice per frame: OpenCV 4.6's FFmpeg reader smears all but the last slice of a
            # frame cut in several (x264's sliced-threads, on with zerolatency; docs/cameras.md).
            self.encoder = (
                "x264enc tune=zerolatency sliced-threads=false speed-preset=ultrafast bframes=0 key-int-max=%d "
                "! video/x-h264,profile=baseline ! rtph264pay name=pay0 pt=96 "
                "config-interval=-1" % key_interval
            )
        else:
            self.encoder = "jpegenc quality=85 ! rtpjpegpay name=pay0 pt=26"
        self.connect("media-configure", self.on_configure)

    def do_create_element(self, url):
        return Gst.parse_launch(
            "appsrc name=src is-live=true format=time do-timestamp=false block=false "
            "caps=%s ! queue max-size-buffers=1 ! %s" % (self.caps, self.encoder)
        )

    def on_configure(self, factory, media):
        source = media.get_element().get_child_by_name("src")
        source.set_property("caps", Gst.Caps.from_string(self.caps))
        state = {"next": 0, "start": None}
        source.connect("need-data", self.on_need_data, state)

    def on_need_data(self, source, length, state):
        # Like a camera, frames are taken at their time: the session starts at the pipeline's
        # running time when the first frame is asked for, and the frames whose time passed while
        # the server held the session (between SETUP and PLAY) are never sent.
        now = source.get_current_running_time()
        if now == Gst.CLOCK_TIME_NONE:
            now = 0
        if state["start"] is None:
            state["start"] = now
        n = state["next"]
        while self.time_of(n + 1) <= now - state["start"]:
            n += 1
        if n >= len(self.frames) and not self.loop:
            source.emit("end-of-stream")
            return
        buffer = self.frames[n % len(self.frames)].copy()
        buffer.pts = state["start"] + self.time_of(n)
        buffer.dts = buffer.pts
        buffer.duration = self.time_of(1)
        state["next"] = n + 1
        source.emit("push-buffer", buffer)

    def time_of(self, n):
        return Gst.util_uint64_scale(n, Gst.SECOND * self.rate[1], self.rate[0])

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--video", required=True, help="the video file to serve")
    parser.add_argument("--mount", action="append", help="a mount point (default: stream)")
    parser.add_argument("--port", type=int, default=0, help="TCP port (0: a free one)")
    parser.add_argument("--width", type=int, default=0, help="scale to this width")
    parser.add_argument("--height", type=int, default=0, help="scale to this height")
    parser.add_argument("--frames", type=int, default=0, help="serve the first N frames only")
    parser.add_argument("--fps", type=float, default=0, help="frame rate (default: the video's)")
    parser.add_argument("--loop", action="store_true", help="start again at the end")
    parser.add_argument("--codec", choices=["h264", "jpeg"], default="h264")
    args = parser.parse_args()
    if (args.width > 0) != (args.height > 0):
        parser.error("give --width and --height together")

    Gst.init(None)
    needed = ["appsrc", "videoconvert", "decodebin"]
    needed += ["x264enc", "rtph264pay"] if args.codec == "h264" else ["jpegenc", "rtpjpegpay"]
    missing = [e for e in needed if Gst.ElementFactory.find(e) is None]
    if missing:
        fail(
            "GStreamer elements missing: %s (gstreamer1.0-plugins-base, -good, -ugly)"
            % ", ".join(missing)
        )
    frames, caps, rate = decode_video(args.video, args.width, args.height, args.frames)
    if args.fps > 0:
        rate = (int(round(args.fps * 1000)), 1000)

    server = GstRtspServer.RTSPServer()
    server.set_address("127.0.0.1")
    server.set_service(str(args.port))
    mounts = server.get_mount_points()
    names = args.mount or ["stream"]
    for name in names:
        mounts.add_factory("/" + name, VideoFactory(frames, caps, rate, args.loop, args.codec))
    loop = GLib.MainLoop()
    if server.attach(None) == 0:
        fail("cannot listen on 127.0.0.1:%d" % args.port)
    base = "rtsp://127.0.0.1:%d" % server.get_bound_port()
    print("ready %s" % base, flush=True)
    for name in names:
        print("mount %s/%s" % (base, name), flush=True)
    for sig in (signal.SIGTERM, signal.SIGINT):
        GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, sig, loop.quit)
    loop.run()


if __name__ == "__main__":
    main()
