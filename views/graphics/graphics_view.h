// Internal: the graphics view, a controller that only reads. It draws the
// items of a tx_view_def from the latest snapshots, at its own rate (30 Hz by
// default), headless on OSMesa (frames as PNG) or in a GLFW window.
//
// Its step never renders: it acquires the snapshots of what it draws and
// hands them to its own rendering thread (SCHED_OTHER, kept off the CPU the
// fastest controller group is pinned to). A snapshot stays valid until the
// next acquire of the same port, so nothing is copied; while a frame is still
// being drawn the step skips its tick and counts a dropped frame. In lockstep
// (params.wait) the step waits instead, so every tick gives a frame.
//
// params (the loader fills them from the scenario's "view" and the command line):
//   view            the scenario's "view" object (docs/views.md)
//   available       components written in the model, for the automatic draw list
//   target          "png" or "window"
//   stereo_mode     mono, sbs, tb, anaglyph, lr
//   wait            true in lockstep
//   render_threads  llvmpipe rasteriser threads, -1 for CPUs - 2 (at most 8)
// Writes OUT/frames/ (see docs/views.md); results: frames, frames_dropped,
// frame_ms_p50, frame_ms_p99, render_threads.
#ifndef TX_VIEWS_GRAPHICS_GRAPHICS_VIEW_H
#define TX_VIEWS_GRAPHICS_GRAPHICS_VIEW_H

#include <tactus/controller.h>

extern const tx_controller_class tx_graphics_view;

#endif
