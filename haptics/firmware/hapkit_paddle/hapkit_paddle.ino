// FeelFlow paddle firmware: a Hapkit-style 1-DOF paddle speaking FeelFlow's serial protocol v1.
//
// Protocol (docs/guide/haptic-devices.md, haptics/protocols/hapkit.py; keep the three in step):
//   frame  = 0xA5 0x5A | version | type | length | payload | crc16 (little-endian)
//   crc16  = CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF) over version, type, length, payload
//   host -> paddle: 0x01 HELLO (empty), 0x02 FORCE (seq u16, force f32 N), 0x03 STOP (empty)
//   paddle -> host: 0x81 INFO (dof u8, x_min f32 m, x_max f32 m, max_force f32 N, firmware u16)
//                   0x82 STATE (seq u16 echoed, x f32 m, buttons u8), one per FORCE/STOP
// Safety on the paddle itself: every force is clamped to MAX_FORCE_N, and the motor is switched
// off when no FORCE frame arrived for 50 ms (host crashed, cable pulled, loop stalled).
//
// Hardware: Hapkit 3 (Arduino Uno-compatible board with an MR position sensor on A2, motor
// driver PWM on pin 5, direction on pin 8). The position code counts the sensor's wrap-arounds
// ("flips") as the Hapkit 3 template sketch does; the calibration line (sector angle from
// sensor counts) and the radii below are the template's nominal values: recalibrate per paddle.
// Serial at 1 000 000 baud: a FORCE (13 bytes) and a STATE (14 bytes) every millisecond need it.

#include <Arduino.h>

static const uint8_t PROTO_VERSION = 1;
static const uint16_t FIRMWARE = 100;
static const float MAX_FORCE_N = 2.0f;      // what this paddle may ever push with
static const float X_MIN_M = -0.04f, X_MAX_M = 0.04f;
static const unsigned long WATCHDOG_MS = 50;

static const int PWM_PIN = 5, DIR_PIN = 8, SENSOR_PIN = A2, BUTTON_PIN = 2;
static const float RH = 0.090f;     // handle length, m
static const float RP = 0.004191f;  // motor pulley radius, m
static const float RS = 0.073152f;  // sector radius, m
static const float FLIP_THRESHOLD = 700;

// ---- position (MR sensor with flip counting) -----------------------------------------------
static int lastRaw = 0, lastLastRaw = 0, flips = 0;
static long updatedPos = 0;
static bool flipped = false;

static void updatePosition() {
  int raw = analogRead(SENSOR_PIN);
  int diff = raw - lastRaw, lastDiff = raw - lastLastRaw;
  if (abs(diff) > FLIP_THRESHOLD && !flipped) {
    flips += (lastDiff > 0) ? -1 : 1;
    flipped = true;
  } else {
    flipped = false;
  }
  updatedPos = raw + flips * 1023L;
  lastLastRaw = lastRaw;
  lastRaw = raw;
}

static float handlePositionM() {
  float sectorDeg = -0.0107f * updatedPos + 4.9513f;  // Hapkit 3 nominal calibration
  return RH * sectorDeg * PI / 180.0f;
}

// ---- motor -----------------------------------------------------------------------------------
static void setForce(float f) {
  if (!(f == f)) f = 0;  // NaN
  f = constrain(f, -MAX_FORCE_N, MAX_FORCE_N);
  float torque = RP / RS * RH * f;           // motor torque for a handle force
  float duty = sqrt(fabs(torque) / 0.03f);    // Hapkit motor's nonlinear compensation
  duty = constrain(duty, 0.0f, 1.0f);
  digitalWrite(DIR_PIN, torque > 0 ? HIGH : LOW);
  analogWrite(PWM_PIN, (int)(duty * 255));
}

// ---- framing ---------------------------------------------------------------------------------
static uint16_t crc16(const uint8_t *d, size_t n) {
  uint16_t crc = 0xFFFF;
  while (n--) {
    crc ^= (uint16_t)(*d++) << 8;
    for (uint8_t i = 0; i < 8; i++) crc = (crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1;
  }
  return crc;
}

static void sendFrame(uint8_t type, const uint8_t *payload, uint8_t len) {
  uint8_t buf[5 + 32 + 2];
  buf[0] = 0xA5; buf[1] = 0x5A; buf[2] = PROTO_VERSION; buf[3] = type; buf[4] = len;
  memcpy(buf + 5, payload, len);
  uint16_t c = crc16(buf + 2, 3 + len);
  buf[5 + len] = c & 0xFF; buf[6 + len] = c >> 8;
  Serial.write(buf, 7 + len);
}

static void sendInfo() {
  uint8_t p[15];
  p[0] = 1;  // dof
  memcpy(p + 1, &X_MIN_M, 4); memcpy(p + 5, &X_MAX_M, 4); memcpy(p + 9, &MAX_FORCE_N, 4);
  p[13] = FIRMWARE & 0xFF; p[14] = FIRMWARE >> 8;
  sendFrame(0x81, p, sizeof p);
}

static void sendState(uint16_t seq) {
  uint8_t p[7];
  float x = handlePositionM();
  p[0] = seq & 0xFF; p[1] = seq >> 8;
  memcpy(p + 2, &x, 4);
  p[6] = digitalRead(BUTTON_PIN) == LOW ? 1 : 0;
  sendFrame(0x82, p, sizeof p);
}

// parser state
static uint8_t rx[5 + 32 + 2];
static uint8_t rxLen = 0;
static unsigned long lastForceMs = 0;
static bool motorOn = false;

static void handleFrame(uint8_t type, const uint8_t *payload, uint8_t len) {
  if (type == 0x01 && len == 0) {
    sendInfo();
  } else if (type == 0x02 && len == 6) {
    uint16_t seq = payload[0] | (payload[1] << 8);
    float f;
    memcpy(&f, payload + 2, 4);
    setForce(f);
    motorOn = true;
    lastForceMs = millis();
    sendState(seq);
  } else if (type == 0x03 && len == 0) {
    setForce(0);
    motorOn = false;
    sendState(0);
  }
}

static void feedByte(uint8_t b) {
  if (rxLen == 0 && b != 0xA5) return;
  if (rxLen == 1 && b != 0x5A) { rxLen = (b == 0xA5) ? 1 : 0; return; }
  rx[rxLen++] = b;
  if (rxLen >= 5 && rx[4] > 32) { rxLen = 0; return; }        // impossible length
  if (rxLen >= 5 && rxLen == 7 + rx[4]) {
    uint16_t got = rx[5 + rx[4]] | (rx[6 + rx[4]] << 8);
    if (got == crc16(rx + 2, 3 + rx[4]) && rx[2] == PROTO_VERSION) handleFrame(rx[3], rx + 5, rx[4]);
    rxLen = 0;
  }
}

void setup() {
  Serial.begin(1000000);
  pinMode(PWM_PIN, OUTPUT);
  pinMode(DIR_PIN, OUTPUT);
  pinMode(BUTTON_PIN, INPUT_PULLUP);
  // faster PWM on pin 5 (Timer0 stays for millis: leave its prescaler)
  setForce(0);
  lastRaw = lastLastRaw = analogRead(SENSOR_PIN);
}

void loop() {
  updatePosition();
  while (Serial.available()) feedByte(Serial.read());
  if (motorOn && millis() - lastForceMs > WATCHDOG_MS) {  // the host went quiet: let go
    setForce(0);
    motorOn = false;
  }
}
