"""tablegen: the direct rebound model and the offline table build."""
