//! The CAN tasks: commands in, status and rejections out, over FDCAN1 in classic mode with
//! the frame layout of [`firmware::can_protocol`].
//!
//! The receive task decodes each frame addressed to this node, serves it with
//! [`firmware::can_server::serve`] (the same code the host tests run) and queues the reply
//! (a status for an accepted command other than a heartbeat or a parameter command, a
//! `Parameter` frame for a parameter get or set, a reject naming the bound for a refused
//! or malformed one). `SaveParameters` writes the flash from this task
//! ([`super::param_flash::save`]), outside the controller's critical section. The transmit task
//! sends queued replies and, when none is due, a status every [`STATUS_PERIOD`]. The
//! command timeout itself is the controller's: heartbeats are forwarded to it like any
//! other command.

use embassy_stm32::can::{Can, CanRx, CanTx, Frame as HalFrame};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{with_timeout, Duration};
use embedded_can::Id;
use firmware::can_protocol::{
    decode_command, encode_reply, Frame, Function, NodeId, Rejection, Reply, Request, Status,
    NO_COMMAND,
};
use firmware::can_server::{save_failed, serve, Response};
use firmware::Mode;

use super::control;
use super::param_flash::{self, Store};

/// Period of the unsolicited status frame.
pub const STATUS_PERIOD: Duration = Duration::from_millis(100);

/// What the receive task asks the transmit task to send.
#[derive(Clone, Copy)]
enum Outgoing {
    /// A status acknowledging a command of this function code.
    Ack(u8),
    /// A reply frame (parameter value or rejection).
    Reply(Reply),
}

static OUTGOING: Channel<CriticalSectionRawMutex, Outgoing, 4> = Channel::new();

/// Splits the started CAN peripheral into the two halves the tasks take.
pub fn split(can: Can<'static>) -> (CanTx<'static>, CanRx<'static>) {
    let (tx, rx, _properties) = can.split();
    (tx, rx)
}

/// Receives and executes commands.
#[embassy_executor::task]
pub async fn receive(mut rx: CanRx<'static>, node: NodeId, mut store: Store) {
    loop {
        let envelope = match rx.read().await {
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

/// Sends replies and the periodic status.
#[embassy_executor::task]
pub async fn transmit(mut tx: CanTx<'static>, node: NodeId) {
    let mut sequence: u8 = 0;
    let mut last_command = NO_COMMAND;
    loop {
        let reply = match with_timeout(STATUS_PERIOD, OUTGOING.receive()).await {
            Ok(Outgoing::Reply(r)) => r,
            Ok(Outgoing::Ack(function)) => {
                last_command = function;
                status(last_command, sequence)
            }
            Err(_timeout) => status(last_command, sequence),
        };
        if matches!(reply, Reply::Status(_)) {
            sequence = sequence.wrapping_add(1);
        }
        let frame = encode_reply(&reply, node);
        if let Ok(hal) = HalFrame::new_standard(frame.id(), frame.payload()) {
            // `write` waits for a free mailbox; a frame displaced by a higher-priority one
            // is dropped, the next status supersedes it.
            let _ = tx.write(&hal).await;
        }
    }
}

fn execute(request: &Request, store: &mut Store) -> Option<Outgoing> {
    match control::with_controller(|c| serve(request, c))? {
        Response::Silent => None,
        Response::Ack(function) => Some(Outgoing::Ack(function)),
        Response::Reply(reply) => Some(Outgoing::Reply(reply)),
        // `serve` checked that the bridge is off; the flash write stalls the CPU ~25 ms.
        Response::Save(values) => match param_flash::save(store, &values) {
            Ok(sequence) => {
                defmt::info!("parameters: table {} saved", sequence);
                Some(Outgoing::Ack(Function::SaveParameters.code()))
            }
            Err(_) => {
                defmt::error!("parameters: flash write failed");
                Some(Outgoing::Reply(save_failed()))
            }
        },
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
