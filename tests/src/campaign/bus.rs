//! The CAN bus between the bench PC and the drive, for the fault campaign: every command
//! reaches the control core as a frame through the firmware's own decoder and server
//! ([`firmware::can_protocol::decode_command`], [`firmware::can_server::serve`]), the way
//! the application's receive task does.
//!
//! Classic CAN at 1 Mbit/s. A data frame with n bytes and an 11-bit identifier is
//! 47 + 8n bits, plus at most ⌊(34 + 8n − 1)/4⌋ stuff bits (ISO 11898-1, worst case): 135 µs
//! for 8 bytes, 55 µs for none. Whenever the bus falls idle the pending frame with the
//! lowest identifier wins arbitration (a node transmits its own queue in order). A frame
//! reaches the drive when its last bit is sent and is served before the next current-loop
//! call (the receive task runs between the control interrupts). The drive answers as its
//! CAN tasks do: a status for an accepted command, a reject for a refused or malformed one,
//! a parameter frame for a parameter request, a status every 100 ms; its transmit queue
//! holds four frames and drops when full. Like the application (which has no identifier
//! filter), it answers every frame the codec names a reject for.

use firmware::can_protocol::{
    decode_command, encode_command, encode_reply, Frame, NodeId, Rejection, Reply, Request, Status,
    NO_COMMAND,
};
use firmware::can_server::{serve, Response};
use firmware::Controller;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::VecDeque;

/// Bit rate. [bit/s]
pub const BIT_RATE: f64 = 1e6;
/// The drive's node number.
pub const DRIVE_NODE: u8 = 1;
/// Period of the drive's unsolicited status frame. [s]
pub const STATUS_PERIOD_S: f64 = 0.1;
/// Frames the drive's transmit queue holds.
const DRIVE_TX_QUEUE: usize = 4;

/// Worst-case length on the wire of a standard data frame with `dlc` bytes. [s]
pub fn frame_time_s(dlc: usize) -> f64 {
    let n = dlc.min(8) as f64;
    let bits = 47.0 + 8.0 * n + ((34.0 + 8.0 * n - 1.0) / 4.0).floor();
    bits / BIT_RATE
}

/// Who sent a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sender {
    Pc,
    Drive,
    Intruder,
}

/// A node that floods the bus: always a frame pending, sent back to back.
#[derive(Clone, Copy, Debug)]
pub struct Babbler {
    /// Its frame.
    pub frame: Frame,
    /// Until when. [s]
    pub until_s: f64,
}

/// Malformed frames arriving at random.
#[derive(Clone, Debug)]
pub struct Garbage {
    /// Mean rate. [frames/s]
    pub rate_hz: f64,
    /// Until when. [s]
    pub until_s: f64,
    rng: Xoshiro256PlusPlus,
    next_s: f64,
}

impl Garbage {
    /// Garbage at `rate_hz` from `from_s` to `until_s`, drawn from `seed`.
    pub fn new(rate_hz: f64, from_s: f64, until_s: f64, seed: u64) -> Garbage {
        let mut g = Garbage {
            rate_hz,
            until_s,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            next_s: from_s,
        };
        g.next_s += g.gap();
        g
    }

    fn unit(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn gap(&mut self) -> f64 {
        -(1.0 - self.unit()).ln() / self.rate_hz.max(1.0)
    }

    /// One malformed frame: for another node, an unknown function of the drive, a known
    /// one with the wrong length, an unknown mode, parameter or loop code.
    fn frame(&mut self) -> Frame {
        let node = u16::from(DRIVE_NODE);
        let mut bytes = [0u8; 8];
        for b in &mut bytes {
            *b = self.rng.next_u64() as u8;
        }
        let kind = self.rng.next_u64() % 6;
        let (id, len) = match kind {
            0 => {
                // Any function, another node.
                let other = (node + 1 + self.rng.next_u64() as u16 % 15) & 0xF;
                ((self.rng.next_u64() as u16 & 0x7F0) | other, bytes.len())
            }
            1 => {
                // An unused function base of the drive.
                const UNUSED: [u16; 6] = [0x150, 0x160, 0x170, 0x280, 0x300, 0x7F0];
                let base = UNUSED[(self.rng.next_u64() % 6) as usize];
                (base | node, (self.rng.next_u64() % 9) as usize)
            }
            2 => {
                // A known function with a length it never has.
                const KNOWN: [(u16, usize); 5] =
                    [(0x100, 1), (0x110, 4), (0x120, 4), (0x200, 5), (0x230, 7)];
                let (base, dlc) = KNOWN[(self.rng.next_u64() % 5) as usize];
                let mut len = (self.rng.next_u64() % 9) as usize;
                if len == dlc {
                    len = (dlc + 1) % 9;
                }
                (base | node, len)
            }
            3 => {
                bytes[0] = 4 + (self.rng.next_u64() % 252) as u8;
                (0x100 | node, 1)
            }
            4 => {
                // A byte that is no parameter's id (0, 6-9, 16-19, …, above the last).
                bytes[0] = loop {
                    let b = self.rng.next_u64() as u8;
                    if firmware::parameters::ParamId::from_code(b).is_none() {
                        break b;
                    }
                };
                let base = if self.rng.next_u64() % 2 == 0 {
                    0x200
                } else {
                    0x210
                };
                (base | node, if base == 0x200 { 5 } else { 1 })
            }
            _ => {
                bytes[0] = 4 + (self.rng.next_u64() % 252) as u8;
                (0x230 | node, 7)
            }
        };
        Frame::new(id, &bytes[..len]).unwrap_or_else(|_| Frame::new(0x7FF, &[]).unwrap())
    }
}

/// What the drive made of the frames it received (for the campaign's checks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriveRx {
    /// Requests served (decoded frames for this drive).
    pub served: u32,
    /// Requests the controller refused.
    pub refused: u32,
    /// Malformed frames for this drive (answered with a reject).
    pub malformed: u32,
    /// Frames for other nodes.
    pub filtered: u32,
    /// Rejects the drive sent for frames addressed to another node.
    pub foreign_replies: u32,
    /// Replies the drive could not queue.
    pub tx_dropped: u32,
}

/// The bus with the bench PC, the drive and any intruders.
#[derive(Clone, Debug)]
pub struct Bus {
    node: NodeId,
    now_s: f64,
    wire: Option<(Frame, Sender, f64)>,
    pc: VecDeque<Frame>,
    drive: VecDeque<Frame>,
    next_status_s: f64,
    status_sequence: u8,
    last_ack: u8,
    /// A flooding node.
    pub babbler: Option<Babbler>,
    /// Garbage frames.
    pub garbage: Option<Garbage>,
    /// The last time a request reached the controller's command path. [s]
    pub last_command_s: f64,
    /// Counts of what the drive received.
    pub rx: DriveRx,
}

impl Default for Bus {
    fn default() -> Self {
        Bus::new()
    }
}

impl Bus {
    /// An idle bus.
    pub fn new() -> Bus {
        Bus {
            node: NodeId::new(DRIVE_NODE).unwrap_or_else(|_| unreachable!("node 1 is valid")),
            now_s: 0.0,
            wire: None,
            pc: VecDeque::new(),
            drive: VecDeque::new(),
            next_status_s: STATUS_PERIOD_S,
            status_sequence: 0,
            last_ack: NO_COMMAND,
            babbler: None,
            garbage: None,
            last_command_s: 0.0,
            rx: DriveRx::default(),
        }
    }

    /// Queues a request from the bench PC.
    pub fn pc_send(&mut self, request: &Request) {
        self.pc.push_back(encode_command(request, self.node));
    }

    /// Queues a raw frame from the bench PC (its own encoding, out-of-range values).
    pub fn pc_send_frame(&mut self, frame: Frame) {
        self.pc.push_back(frame);
    }

    /// Frames waiting in the PC's queue.
    pub fn pc_pending(&self) -> usize {
        self.pc.len()
    }

    /// Runs the bus up to `until_s`, serving every frame that completes on `controller`.
    pub fn run_until(&mut self, until_s: f64, controller: &mut Controller) {
        while self.now_s < until_s {
            if let Some((frame, sender, end)) = self.wire {
                if end > until_s {
                    break;
                }
                self.now_s = end;
                self.wire = None;
                if sender != Sender::Drive {
                    self.receive(&frame, controller);
                }
                continue;
            }
            if self.next_status_s <= self.now_s {
                self.queue_status(controller);
                self.next_status_s += STATUS_PERIOD_S;
            }
            match self.arbitrate() {
                Some((frame, sender)) => {
                    let end = self.now_s + frame_time_s(frame.payload().len());
                    self.wire = Some((frame, sender, end));
                }
                None => {
                    // Idle until the next thing that can happen.
                    let mut next = until_s.min(self.next_status_s);
                    if let Some(g) = &self.garbage {
                        if g.next_s < g.until_s {
                            next = next.min(g.next_s);
                        }
                    }
                    self.now_s = next.max(self.now_s);
                    if self.now_s >= until_s {
                        break;
                    }
                }
            }
        }
        self.now_s = self.now_s.max(until_s);
    }

    /// The pending frame with the lowest identifier, taken off its queue.
    fn arbitrate(&mut self) -> Option<(Frame, Sender)> {
        let now = self.now_s;
        let mut best: Option<(u16, Sender)> = None;
        let mut consider = |id: u16, s: Sender| {
            if best.is_none_or(|(b, _)| id < b) {
                best = Some((id, s));
            }
        };
        if let Some(f) = self.pc.front() {
            consider(f.id(), Sender::Pc);
        }
        if let Some(f) = self.drive.front() {
            consider(f.id(), Sender::Drive);
        }
        let babble = self.babbler.filter(|b| now < b.until_s).map(|b| b.frame);
        if let Some(f) = babble {
            consider(f.id(), Sender::Intruder);
        }
        let garbage_due = self
            .garbage
            .as_ref()
            .is_some_and(|g| g.next_s <= now && g.next_s < g.until_s);
        let garbage_frame = if garbage_due {
            self.garbage.as_mut().map(|g| g.frame())
        } else {
            None
        };
        if let Some(f) = garbage_frame {
            consider(f.id(), Sender::Intruder);
        }
        let (_, sender) = best?;
        let frame = match sender {
            Sender::Pc => self.pc.pop_front(),
            Sender::Drive => self.drive.pop_front(),
            Sender::Intruder => {
                // The babbler's and the garbage's frames compete; the lower id goes.
                match (babble, garbage_frame) {
                    (Some(b), Some(g)) if g.id() < b.id() => {
                        self.advance_garbage();
                        Some(g)
                    }
                    (Some(b), _) => Some(b),
                    (None, Some(g)) => {
                        self.advance_garbage();
                        Some(g)
                    }
                    (None, None) => None,
                }
            }
        }?;
        Some((frame, sender))
    }

    fn advance_garbage(&mut self) {
        if let Some(g) = &mut self.garbage {
            let gap = g.gap();
            g.next_s += gap;
        }
    }

    /// The drive's status frame (its transmit task's, with the last acknowledged command).
    fn queue_status(&mut self, controller: &Controller) {
        let t = controller.telemetry();
        let status = Reply::Status(Status::from_si(
            controller.mode(),
            controller.fault().map_or(0, |f| f.code()),
            t.p_pa,
            t.speed_rad_s,
            self.last_ack,
            self.status_sequence,
        ));
        self.status_sequence = self.status_sequence.wrapping_add(1);
        self.queue_reply(&status);
    }

    fn queue_reply(&mut self, reply: &Reply) {
        if self.drive.len() >= DRIVE_TX_QUEUE {
            self.rx.tx_dropped += 1;
        } else {
            self.drive.push_back(encode_reply(reply, self.node));
        }
    }

    /// The drive's receive task for one frame.
    fn receive(&mut self, frame: &Frame, controller: &mut Controller) {
        match decode_command(frame, self.node) {
            Ok(request) => {
                self.rx.served += 1;
                if request.to_command().is_some() {
                    self.last_command_s = self.now_s;
                }
                match serve(&request, controller) {
                    Response::Silent => {}
                    Response::Ack(function) => {
                        self.last_ack = function;
                        self.queue_status(controller);
                    }
                    Response::Reply(reply) => {
                        if matches!(reply, Reply::Reject(_)) {
                            self.rx.refused += 1;
                        }
                        self.queue_reply(&reply);
                    }
                    // No flash here: the table is not stored (the bench would answer).
                    Response::Save(_) => {}
                }
            }
            Err(err) => {
                let ours = frame.id() & 0xF == u16::from(self.node.get());
                if ours {
                    self.rx.malformed += 1;
                } else {
                    self.rx.filtered += 1;
                }
                // As the application's receive task: a reject whenever the codec names one.
                if let Some(r) = Rejection::for_decode_error(&err) {
                    if !ours {
                        self.rx.foreign_replies += 1;
                    }
                    self.queue_reply(&Reply::Reject(r));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::{Config, Mode};

    #[test]
    fn frame_times_are_the_worst_case_stuffed_lengths() {
        // 8 bytes: 111 bits + 24 stuff bits; 0 bytes: 47 + 8 stuff bits.
        assert!((frame_time_s(8) - 135e-6).abs() < 1e-12);
        assert!((frame_time_s(0) - 55e-6).abs() < 1e-12);
    }

    #[test]
    fn a_babbler_below_the_heartbeat_starves_it_one_above_does_not() {
        for (id, starved) in [(0x080u16, true), (0x600, false)] {
            let mut c = Controller::new(&Config::nominal());
            let mut bus = Bus::new();
            bus.babbler = Some(Babbler {
                frame: Frame::new(id, &[0; 8]).unwrap(),
                until_s: 1.0,
            });
            bus.pc_send(&Request::Heartbeat);
            bus.run_until(0.01, &mut c);
            assert_eq!(bus.pc_pending() == 1, starved, "babbler at {id:#x}");
        }
    }

    #[test]
    fn commands_reach_the_controller_and_garbage_does_not() {
        // A drive brought up as the closed-loop runs bring it up (sensor zeros trusted,
        // encoder referenced, no bootstrap wait): the bring-up rules refuse a running mode
        // before that.
        let config = closed_loop::controller_config(&plant_model::Rig::nominal());
        let mut c = Controller::new(&config);
        let mut bus = Bus::new();
        bus.pc_send(&Request::SetMode(Mode::Speed));
        bus.run_until(1e-3, &mut c);
        assert_eq!(c.mode(), Mode::Speed);
        assert!(bus.last_command_s > 0.0);
        bus.garbage = Some(Garbage::new(5000.0, 1e-3, 0.2, 7));
        bus.run_until(0.2, &mut c);
        assert_eq!(c.mode(), Mode::Speed);
        assert_eq!(bus.rx.served, 1, "{:?}", bus.rx);
        assert!(bus.rx.malformed + bus.rx.filtered > 200, "{:?}", bus.rx);
    }
}
