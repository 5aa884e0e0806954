"""AIS in and out: NMEA 0183 ``!AIVDM``/``!AIVDO`` messages, the reporting rules, logged tracks."""
