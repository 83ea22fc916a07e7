# Sourced by the window tests: xvfb_next sets xvfb_display to a display
# number of its own for the next `xvfb-run -a -n "$xvfb_display"`. xvfb-run
# stops its Xvfb without waiting for it, and a server still tearing down
# unlinks its socket (/tmp/.X11-unix/XN): a run started meanwhile on the
# same number (xvfb-run -a alone takes the lowest without a lock file)
# cannot open its display, as a loaded CI machine showed. Each run here
# starts its search past the last one's, at a number with no lock and no
# socket.
xvfb_display=${xvfb_display:-99}
xvfb_next() {
  local n=$((xvfb_display + 1))
  while [ -e "/tmp/.X$n-lock" ] || [ -e "/tmp/.X11-unix/X$n" ]; do n=$((n + 1)); done
  xvfb_display=$n
}
