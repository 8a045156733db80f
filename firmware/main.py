# Runs at boot (after boot.py): start the robot's command loop on the USB serial console.
import robot

robot.main()
