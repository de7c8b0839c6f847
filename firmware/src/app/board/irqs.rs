//! The interrupt bindings of the HAL's drivers (FDCAN1 and the phase comparators). The
//! current loop's own vector (ADC1_2) is bound by the application, which joins the board
//! to the control interrupt.

use embassy_stm32::bind_interrupts;
use embassy_stm32::can;
use embassy_stm32::comp;
use embassy_stm32::peripherals::{COMP1, COMP3, COMP4, FDCAN1};

bind_interrupts!(pub struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
    COMP1_2_3 => comp::InterruptHandler<COMP1>, comp::InterruptHandler<COMP3>;
    COMP4_5_6 => comp::InterruptHandler<COMP4>;
});
