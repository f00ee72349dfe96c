// FeelFlow DIY HID force board: pose in, force out, over vendor-defined 64-byte HID reports.
//
// Protocol v1 (docs/guide/haptic-devices.md, haptics/protocols/diyhid.py; keep the three in step). Raw
// 64-byte reports, no report ids, little-endian:
//   board -> host  STATE 0x01: version, seq u8, x i32 um, y i32 um, angle i16 mrad, buttons u8, status u8
//                  INFO  0x83: version, dof u8, max_force u16 mN, x_min, x_max, y_min, y_max i32 um
//   host -> board  FORCE 0x02: version, seq u8, fx i16 mN, fy i16 mN, flags u8 (bit 0: enable)
//                  INFO_REQUEST 0x03: version          (the board answers INFO)
// The board streams STATE every millisecond, clamps |F| to MAX_FORCE_N and drops the motors
// when no FORCE report came for 50 ms.
//
// Board: a Teensy (3.2, 4.0, LC) with Tools > USB Type = "Raw HID" (Teensyduino: usage page
// 0xFFAB, usage 0x0200, VID:PID 16c0:0486; FeelFlow finds it by that usage page).
// Mechanics assumed here: a belt-driven XY stage, one quadrature encoder and one DC motor per
// axis (PWM + direction). Adapt METRES_PER_COUNT, NEWTONS_AT_FULL_PWM and the pins to yours;
// for a linkage, replace poseFromEncoders()/motorCommands() with its kinematics.

#include <Encoder.h>

static const uint8_t VERSION = 1;
static const float MAX_FORCE_N = 3.0f;
static const float X_MIN = -0.05f, X_MAX = 0.05f, Y_MIN = -0.04f, Y_MAX = 0.04f;  // metres
static const float METRES_PER_COUNT = 2.0e-5f;   // belt pitch x pulley teeth / counts per rev
static const float NEWTONS_AT_FULL_PWM = 4.0f;   // measure with a spring scale
static const unsigned long WATCHDOG_US = 50000;

static const int PWM_X = 3, DIR_X = 4, PWM_Y = 5, DIR_Y = 6, BUTTON_PIN = 9;
Encoder encX(7, 8), encY(10, 11);

static uint8_t in[64], out[64];
static uint8_t seq = 0;
static unsigned long lastForceUs = 0, lastStateUs = 0;
static bool enabled = false;

static void put32(uint8_t *p, int32_t v) { memcpy(p, &v, 4); }
static void put16(uint8_t *p, int16_t v) { memcpy(p, &v, 2); }

static void drive(int pwmPin, int dirPin, float f) {
  float duty = constrain(fabs(f) / NEWTONS_AT_FULL_PWM, 0.0f, 1.0f);
  digitalWrite(dirPin, f >= 0 ? HIGH : LOW);
  analogWrite(pwmPin, (int)(duty * 255));
}

static void setForce(float fx, float fy) {
  if (!(fx == fx) || !(fy == fy)) fx = fy = 0;  // NaN
  float mag = sqrt(fx * fx + fy * fy);
  if (mag > MAX_FORCE_N) { fx *= MAX_FORCE_N / mag; fy *= MAX_FORCE_N / mag; }
  drive(PWM_X, DIR_X, fx);
  drive(PWM_Y, DIR_Y, fy);
}

static void sendInfo() {
  memset(out, 0, 64);
  out[0] = 0x83; out[1] = VERSION; out[2] = 2;
  uint16_t mn = (uint16_t)(MAX_FORCE_N * 1000);
  memcpy(out + 3, &mn, 2);
  put32(out + 5, (int32_t)(X_MIN * 1e6)); put32(out + 9, (int32_t)(X_MAX * 1e6));
  put32(out + 13, (int32_t)(Y_MIN * 1e6)); put32(out + 17, (int32_t)(Y_MAX * 1e6));
  RawHID.send(out, 10);
}

static void sendState() {
  memset(out, 0, 64);
  float x = encX.read() * METRES_PER_COUNT, y = encY.read() * METRES_PER_COUNT;
  out[0] = 0x01; out[1] = VERSION; out[2] = ++seq;
  put32(out + 3, (int32_t)(x * 1e6));
  put32(out + 7, (int32_t)(y * 1e6));
  put16(out + 11, 0);
  out[13] = digitalRead(BUTTON_PIN) == LOW ? 1 : 0;
  out[14] = enabled ? 1 : 0;
  RawHID.send(out, 0);
}

void setup() {
  pinMode(PWM_X, OUTPUT); pinMode(DIR_X, OUTPUT);
  pinMode(PWM_Y, OUTPUT); pinMode(DIR_Y, OUTPUT);
  pinMode(BUTTON_PIN, INPUT_PULLUP);
  analogWriteResolution(8);
  setForce(0, 0);
}

void loop() {
  if (RawHID.recv(in, 0) > 0 && in[1] == VERSION) {
    if (in[0] == 0x02) {
      int16_t fx, fy;
      memcpy(&fx, in + 3, 2); memcpy(&fy, in + 5, 2);
      enabled = in[7] & 1;
      setForce(enabled ? fx * 1e-3f : 0, enabled ? fy * 1e-3f : 0);
      lastForceUs = micros();
    } else if (in[0] == 0x03) {
      sendInfo();
    }
  }
  if (enabled && micros() - lastForceUs > WATCHDOG_US) {  // the host went quiet: let go
    setForce(0, 0);
    enabled = false;
  }
  if (micros() - lastStateUs >= 1000) {
    lastStateUs += 1000;
    sendState();
  }
}
