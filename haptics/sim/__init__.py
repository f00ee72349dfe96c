"""Simulated devices that speak each real protocol, for classes without hardware and for tests.

Serial ones (haply2diy, hapkit) sit behind a real pseudo-terminal (os.openpty): the driver opens
the pty's tty with pyserial exactly as it would /dev/ttyACM0. `sim://` URLs run them in their own
process (haptics.sim.serve), independent of the host as a real board is; tests may also create
them in-process (HaplySim(), HapkitSim()). HID ones (spacemouse, diyhid)
stand at the hidapi boundary: objects with the hid.device methods the transport uses.
Each has a simulated hand: `set_hand(x, y)` moves the handle (metres, device frame), and
records what the host commanded (`max_force_seen`, `last_force`).
"""
