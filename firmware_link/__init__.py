"""The only package that speaks MAVLink to the vehicle (pymavlink, pyserial)."""
