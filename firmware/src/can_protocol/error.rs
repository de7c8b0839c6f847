//! Why a frame cannot be decoded ([`DecodeError`]): its shape (identifier, length,
//! node) or a code that does not exist.

use super::function::Function;

/// A frame the codec cannot turn into a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// Identifier wider than 11 bits.
    IdentifierTooLarge {
        /// The identifier.
        id: u32,
    },
    /// More than 8 data bytes.
    PayloadTooLong {
        /// Offered length. [bytes]
        len: usize,
    },
    /// Node number above [`super::wire::NODE_MAX`].
    NodeOutOfRange {
        /// The offered node number.
        node: u8,
    },
    /// The frame is addressed to another node.
    OtherNode {
        /// Node number in the identifier.
        node: u8,
    },
    /// The identifier's function is not a command (when decoding commands) or not a reply
    /// (when decoding replies).
    UnknownFunction {
        /// The identifier.
        id: u16,
    },
    /// The data length does not match the function.
    WrongLength {
        /// The function of the frame.
        function: Function,
        /// Required data length. [bytes]
        expected: u8,
        /// Received data length. [bytes]
        got: u8,
    },
    /// A reply frame whose data length is not 8.
    WrongReplyLength {
        /// Received data length. [bytes]
        got: u8,
    },
    /// A `SetMode` frame with a mode code above [`super::wire::MODE_CODE_MAX`].
    UnknownMode {
        /// The received code.
        code: u8,
    },
    /// A reject frame with an unknown reason code.
    UnknownReason {
        /// The received code.
        code: u8,
    },
    /// A reject frame whose reserved bytes are not zero.
    ReservedNotZero,
    /// A parameter id or step-test loop code that does not exist.
    UnknownCode {
        /// The function of the frame.
        function: Function,
        /// The received code.
        code: u8,
    },
}
