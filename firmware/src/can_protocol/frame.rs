//! A classic CAN data frame with an 11-bit identifier, independent of any CAN driver,
//! the node number a drive answers to, and the acceptance filters that pass exactly its
//! commands.

use super::error::DecodeError;
use super::id;
use super::wire::{MAX_DLC, NODE_MASK, NODE_MAX, STANDARD_ID_MAX};

/// A classic CAN data frame with an 11-bit identifier, independent of any CAN driver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    pub(super) id: u16,
    pub(super) len: u8,
    pub(super) data: [u8; MAX_DLC],
}

impl Frame {
    /// Builds a frame; fails if the identifier is not 11-bit or the payload exceeds 8 bytes.
    pub fn new(id: u16, payload: &[u8]) -> Result<Frame, DecodeError> {
        if id > STANDARD_ID_MAX {
            return Err(DecodeError::IdentifierTooLarge { id: u32::from(id) });
        }
        let mut data = [0u8; MAX_DLC];
        let Some(dst) = data.get_mut(..payload.len()) else {
            return Err(DecodeError::PayloadTooLong { len: payload.len() });
        };
        dst.copy_from_slice(payload);
        // `get_mut(..len)` succeeded, so `len <= 8` and the cast is lossless.
        Ok(Frame {
            id,
            len: payload.len() as u8,
            data,
        })
    }

    /// The 11-bit identifier.
    pub fn id(&self) -> u16 {
        self.id
    }

    /// The payload (DLC bytes).
    pub fn payload(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

/// The frame in the `cansend`/`candump` notation of Linux SocketCAN: three hex digits of
/// identifier, `#`, the payload in hex (`203#0A0000803E`), so a printed command can be
/// sent with `cansend can0 <frame>`.
impl core::fmt::Display for Frame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:03X}#", self.id)?;
        for b in self.payload() {
            write!(f, "{b:02X}")?;
        }
        Ok(())
    }
}

/// Node number of a drive on the bus (0‥15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeId(pub(super) u8);

impl NodeId {
    /// Validates a node number.
    pub fn new(node: u8) -> Result<NodeId, DecodeError> {
        if node > NODE_MAX {
            Err(DecodeError::NodeOutOfRange { node })
        } else {
            Ok(NodeId(node))
        }
    }

    /// The node number.
    pub fn get(self) -> u8 {
        self.0
    }

    pub(super) fn id(self, base: u16) -> u16 {
        base | u16::from(self.0)
    }
}

/// Standard-identifier acceptance filters, as (identifier, mask) pairs (a frame passes when
/// `id & mask == identifier & mask`), that pass exactly the command blocks of `node`: the
/// real-time commands `0x100`‥`0x170` and the configuration commands `0x200`‥`0x270` with
/// its node number. Replies, other nodes' frames and every other identifier stay in the
/// controller's filter, out of the drive's receive FIFO; a free function code of these
/// blocks still reaches the drive, which rejects it as unknown.
pub fn acceptance_filters(node: NodeId) -> [(u16, u16); 2] {
    // Bits 10..7 select the block, bits 3..0 the node.
    const MASK: u16 = 0x780 | NODE_MASK;
    [
        (node.id(id::SET_MODE), MASK),
        (node.id(id::SET_PARAMETER), MASK),
    ]
}
