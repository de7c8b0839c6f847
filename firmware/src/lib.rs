//! EHA motor-drive control core: hardware-free, `no_std`, linked by the MCU application,
//! the host simulator, the tests and the PIL binary.
#![cfg_attr(not(test), no_std)]
pub mod can_protocol;
