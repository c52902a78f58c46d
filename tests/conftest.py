"""Every test process can fly lockstep: the bundled SITL is handed to the station as the
`quadgcs` console script hands it (`lab.lockstep.install`)."""

from lab.lockstep import install

install()
