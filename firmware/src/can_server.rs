//! The drive's side of the CAN protocol ([`crate::can_protocol`]): what a decoded request
//! does to the controller and which reply goes back. Hardware-free, so the MCU
//! application and the host tests run the same code; only saving to flash is left to the
//! caller ([`Response::Save`]), because the flash is the application's.

use crate::can_protocol::{Function, RejectReason, Rejection, Reply, Request};
use crate::controller::Controller;
use crate::parameters::{self, COUNT};
use crate::supervisor::Mode;

/// What to do after a request was served.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Response {
    /// Send nothing (an accepted heartbeat: the periodic status reports anyway).
    Silent,
    /// Send a status acknowledging the command of this function code.
    Ack(u8),
    /// Send this reply.
    Reply(Reply),
    /// Write this table (in [`parameters::ParamId::ALL`] order) to the parameter store,
    /// then acknowledge `SaveParameters` or reject it with [`save_failed`].
    Save([f32; COUNT]),
}

/// Serves `request` on `controller`.
///
/// `SaveParameters` is allowed in Disabled only: on the G474 a save blocks the tasks for
/// about 50 ms (two page erases; the current loop runs on from the other flash bank), in
/// which the command timeout and the CAN replies wait, which only a drive with its bridge
/// off can afford. It is refused with reason `NotAllowed` and the bound `0` (the Disabled
/// mode code) otherwise.
pub fn serve(request: &Request, controller: &mut Controller) -> Response {
    match *request {
        Request::GetParameter { id } => Response::Reply(Reply::Parameter {
            id,
            value: controller.parameter(id),
        }),
        Request::SaveParameters => {
            if controller.mode() == Mode::Disabled {
                Response::Save(parameters::snapshot(controller.config()))
            } else {
                Response::Reply(Reply::Reject(Rejection::with_si_bound(
                    Function::SaveParameters,
                    RejectReason::NotAllowed,
                    f32::from(Mode::Disabled.code()),
                    0,
                )))
            }
        }
        _ => {
            let Some(command) = request.to_command() else {
                return Response::Silent;
            };
            match controller.command(command) {
                Ok(()) => match *request {
                    Request::Heartbeat => Response::Silent,
                    Request::SetParameter { id, .. } => Response::Reply(Reply::Parameter {
                        id,
                        value: controller.parameter(id),
                    }),
                    _ => Response::Ack(request.function().code()),
                },
                Err(e) => Response::Reply(Reply::Reject(Rejection::for_command_error(request, &e))),
            }
        }
    }
}

/// The reply to a `SaveParameters` whose flash write failed (reason `Invalid`, bound 0).
pub fn save_failed() -> Reply {
    Reply::Reject(Rejection::with_si_bound(
        Function::SaveParameters,
        RejectReason::Invalid,
        0.0,
        0,
    ))
}
