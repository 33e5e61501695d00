"""The numerics of the compliant contact (docs/stability.md, docs/contact_laws.md).

stability_maps  where each explicit method stops walking; friction chatter; energy balance
calibration     drop tests of the normal contact laws, calibration to the paper's ground
"""
