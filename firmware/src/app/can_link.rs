//! The CAN tasks: commands in, status and rejections out, over FDCAN1 in classic mode with
//! the frame layout of [`firmware::can_protocol`].
//!
//! The receive task decodes each frame addressed to this node, serves it with
//! [`firmware::can_server::serve`] (the same code the host tests run) and queues the reply
//! (a status for an accepted command other than a heartbeat or a parameter command, a
//! `Parameter` frame for a parameter get or set, a reject naming the bound for a refused
//! or malformed one). `SaveParameters` writes the flash from this task
//! ([`super::param_flash::save`]), outside the controller's critical section. The transmit task
//! sends queued replies and, when none is due, a status every [`STATUS_PERIOD`], and every
//! [`DIAGNOSTICS_EVERY`]-th of those a `Diagnostics` frame (the stack's high-water mark,
//! [`super::supervision::stack_use`]). The
//! command timeout itself is the controller's: heartbeats are forwarded to it like any
//! other command.
//!
//! The FDCAN's acceptance filter passes only this node's command frames
//! ([`firmware::can_protocol::acceptance_filters`], set in [`super::board`]), and its
//! interrupt moves them from the three-deep hardware FIFO into a queue of [`RX_QUEUE`]
//! frames, so a burst that arrives while a parameter save blocks the tasks for ~50 ms is
//! kept, not overwritten.

use embassy_stm32::can::{
    BufferedCan, BufferedCanSender, CanConfigurator, Frame as HalFrame, RxBuf, TxBuf,
};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{with_timeout, Duration};
use embedded_can::Id;
use firmware::can_protocol::{
    decode_command, encode_reply, Diagnostics, Frame, Function, NodeId, Rejection, Reply, Request,
    Status, NO_COMMAND,
};
use firmware::can_server::{save_failed, serve, Response};
use firmware::Mode;

use super::control;
use super::param_flash::{self, Store};
use super::supervision;

/// Period of the unsolicited status frame.
pub const STATUS_PERIOD: Duration = Duration::from_millis(100);
/// Received frames held between the CAN interrupt and the receive task.
pub const RX_QUEUE: usize = 16;
/// Frames held between the transmit task and the CAN interrupt.
pub const TX_QUEUE: usize = 4;
/// Unsolicited statuses per `Diagnostics` frame (one a second).
pub const DIAGNOSTICS_EVERY: u32 = 10;

/// The started CAN peripheral with its queues, as the receive task reads it.
pub type Link = BufferedCan<'static, TX_QUEUE, RX_QUEUE>;

/// What the receive task asks the transmit task to send.
#[derive(Clone, Copy)]
enum Outgoing {
    /// A status acknowledging a command of this function code.
    Ack(u8),
    /// A reply frame (parameter value or rejection).
    Reply(Reply),
}

static OUTGOING: Channel<CriticalSectionRawMutex, Outgoing, 4> = Channel::new();

/// Starts the CAN peripheral with its queues; returns the link for the receive task and
/// the sender for the transmit task. Called once (its queues are static).
pub fn start(can: CanConfigurator<'static>) -> (Link, BufferedCanSender) {
    let tx = cortex_m::singleton!(: TxBuf<TX_QUEUE> = TxBuf::new());
    let rx = cortex_m::singleton!(: RxBuf<RX_QUEUE> = RxBuf::new());
    let (Some(tx), Some(rx)) = (tx, rx) else {
        defmt::panic!("CAN started twice");
    };
    let link = can.into_normal_mode().buffered(tx, rx);
    let sender = link.writer();
    (link, sender)
}

/// Receives and executes commands. `store` is `None` when the flash has no parameter
/// store (fault 18); a save is then refused.
#[embassy_executor::task]
pub async fn receive(mut link: Link, node: NodeId, mut store: Option<Store>) {
    loop {
        let envelope = match link.read().await {
            Ok(e) => e,
            Err(e) => {
                defmt::warn!("CAN bus error: {}", e);
                continue;
            }
        };
        let Some(frame) = to_protocol_frame(&envelope.frame) else {
            continue;
        };
        let outgoing = match decode_command(&frame, node) {
            Ok(request) => execute(&request, &mut store),
            Err(err) => {
                Rejection::for_decode_error(&err).map(|r| Outgoing::Reply(Reply::Reject(r)))
            }
        };
        if let Some(o) = outgoing {
            // A full queue means the bus is saturated; the periodic status still reports.
            let _ = OUTGOING.try_send(o);
        }
    }
}

/// Sends replies, the periodic status and the diagnostics.
#[embassy_executor::task]
pub async fn transmit(mut tx: BufferedCanSender, node: NodeId) {
    let mut sequence: u8 = 0;
    let mut last_command = NO_COMMAND;
    let mut periodic: u32 = 0;
    loop {
        let (reply, unsolicited) = match with_timeout(STATUS_PERIOD, OUTGOING.receive()).await {
            Ok(Outgoing::Reply(r)) => (r, false),
            Ok(Outgoing::Ack(function)) => {
                last_command = function;
                (status(last_command, sequence), false)
            }
            Err(_timeout) => (status(last_command, sequence), true),
        };
        if matches!(reply, Reply::Status(_)) {
            sequence = sequence.wrapping_add(1);
        }
        send(&mut tx, &reply, node).await;
        if unsolicited {
            periodic = periodic.wrapping_add(1);
            if periodic % DIAGNOSTICS_EVERY == 0 {
                let stack = supervision::stack_use();
                let diagnostics = Diagnostics {
                    stack_peak_bytes: stack.peak_bytes,
                    stack_size_bytes: stack.size_bytes,
                };
                send(&mut tx, &Reply::Diagnostics(diagnostics), node).await;
            }
        }
    }
}

/// Queues one reply for the CAN interrupt, waiting for room.
async fn send(tx: &mut BufferedCanSender, reply: &Reply, node: NodeId) {
    let frame = encode_reply(reply, node);
    if let Ok(hal) = HalFrame::new_standard(frame.id(), frame.payload()) {
        tx.write(hal).await;
    }
}

fn execute(request: &Request, store: &mut Option<Store>) -> Option<Outgoing> {
    match control::with_controller(|c| serve(request, c))? {
        Response::Silent => None,
        Response::Ack(function) => Some(Outgoing::Ack(function)),
        Response::Reply(reply) => Some(Outgoing::Reply(reply)),
        // `serve` checked that the bridge is off; the two erases block the tasks ~50 ms.
        Response::Save(values) => {
            let Some(store) = store.as_mut() else {
                defmt::error!("parameters: no parameter store (fault 18), not saved");
                return Some(Outgoing::Reply(save_failed()));
            };
            match param_flash::save(store, &values) {
                Ok(sequence) => {
                    defmt::info!("parameters: table {} saved", sequence);
                    Some(Outgoing::Ack(Function::SaveParameters.code()))
                }
                Err(_) => {
                    defmt::error!("parameters: flash write failed");
                    Some(Outgoing::Reply(save_failed()))
                }
            }
        }
    }
}

fn status(last_command: u8, sequence: u8) -> Reply {
    let snapshot = control::with_controller(|c| (c.mode(), c.fault(), c.telemetry()));
    let (mode, fault, p_pa, speed) = match snapshot {
        Some((mode, fault, t)) => (mode, fault.map_or(0, |f| f.code()), t.p_pa, t.speed_rad_s),
        None => (Mode::Disabled, 0, 0.0, 0.0),
    };
    Reply::Status(Status::from_si(
        mode,
        fault,
        p_pa,
        speed,
        last_command,
        sequence,
    ))
}

/// Classic data frames with a standard identifier only; anything else is not part of the
/// protocol and is ignored.
fn to_protocol_frame(hal: &HalFrame) -> Option<Frame> {
    if hal.header().rtr() || hal.header().fdcan() {
        return None;
    }
    match hal.id() {
        Id::Standard(id) => Frame::new(id.as_raw(), hal.data()).ok(),
        Id::Extended(_) => None,
    }
}
